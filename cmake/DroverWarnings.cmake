# Warnings on and treated as errors for Drover's own code. Generated code (fastddsgen)
# is compiled without this function so third-party style never breaks the build.
function(drover_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wnon-virtual-dtor -Werror)
endfunction()
