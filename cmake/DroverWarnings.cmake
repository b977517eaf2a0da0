# Warnings on and treated as errors for Drover's own code. Generated code (fastddsgen)
# is compiled without this function so third-party style never breaks the build.
function(drover_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wnon-virtual-dtor -Werror)
  # GCC 12 (Debian bookworm) at -O3, a Release build, warns inside library code inlined into
  # ours: -Wrestrict on `"text" + std::string(...)` in libstdc++ (GCC bug 105329, fixed in
  # GCC 13) and -Wmaybe-uninitialized in Boost.Geometry's is_valid. False positives that made
  # `DROVER_BUILD_TYPE=Release scripts/build.sh` fail; the latter stays a warning there.
  target_compile_options(${target} PRIVATE
    $<$<AND:$<CXX_COMPILER_ID:GNU>,$<VERSION_LESS:$<CXX_COMPILER_VERSION>,13>>:-Wno-restrict>
    $<$<AND:$<CXX_COMPILER_ID:GNU>,$<CONFIG:Release>>:-Wno-error=maybe-uninitialized>)
endfunction()
