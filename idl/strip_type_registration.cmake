# Removes the type-object registration that fastddsgen 2.3 (-typeobject) puts into every
# default constructor of a generated struct ("Just to register all known types"). It
# rebuilds the file's TypeObjects under Fast DDS's locks on each construction: 10-50 us per
# message object, paid for every sample taken and every element of a sequence. The types
# are registered once per process instead (register_all_type_objects(), called by
# drover::dds::Participant::create). Usage: cmake -DDIR=<generated dir> -P this file.

file(GLOB sources "${DIR}/*.cxx")
foreach(source IN LISTS sources)
  file(READ "${source}" text)
  string(REGEX REPLACE
    "\n[ \t]*// Just to register all known types\n[ \t]*register[A-Za-z0-9_]*Types\\(\\);" ""
    stripped "${text}")
  if(NOT stripped STREQUAL text)
    file(WRITE "${source}" "${stripped}")
  endif()
endforeach()
