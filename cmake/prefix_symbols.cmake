# prefix_symbols.cmake - a copy of a static library whose defined global symbols carry a prefix,
# so that two builds of the library (DIM = 2 and DIM = 3) link into one binary
# (docs/development.md, "Dimensions"). References inside the archive are renamed with them.
#
#   cmake -DNM=nm -DOBJCOPY=objcopy -DINPUT=lib.a -DOUTPUT=out.a -DPREFIX=dim3_ [-DMATCH=^mixsph_]
#         -P prefix_symbols.cmake
#   cmake -DOBJCOPY=objcopy -DINPUT=test.o -DOUTPUT=test_renamed.o -DMAP=out.a.map -P prefix_symbols.cmake
#
# MATCH (a regular expression) limits the renaming to the symbols it matches (the 2D build renames
# only its public API, which the dispatcher lib/src/sim_dimension.c then defines). The map of the
# renaming is written beside OUTPUT (OUTPUT.map); the second form renames with such a map an
# object compiled against the archive (a DIM = 3 test: its calls then reach the renamed archive).
foreach(var OBJCOPY INPUT OUTPUT)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "prefix_symbols.cmake: ${var} is not set")
  endif()
endforeach()
if(DEFINED MAP)
  execute_process(COMMAND ${OBJCOPY} --redefine-syms=${MAP} ${INPUT} ${OUTPUT} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "prefix_symbols.cmake: ${OBJCOPY} failed on ${INPUT} (map ${MAP})")
  endif()
  return()
endif()
foreach(var NM PREFIX)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "prefix_symbols.cmake: ${var} is not set")
  endif()
endforeach()
execute_process(COMMAND ${NM} -g --defined-only ${INPUT} OUTPUT_VARIABLE listing RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "prefix_symbols.cmake: ${NM} failed on ${INPUT}")
endif()
string(REPLACE ";" "\\;" listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")
set(map "")
set(seen "")
foreach(line IN LISTS lines)
  # "<address> <type> <name>"; member headers ("file.o:") and blank lines do not match
  if(line MATCHES "^[0-9a-fA-F]+ [A-Za-z] (.+)$")
    set(name "${CMAKE_MATCH_1}")
    if(DEFINED MATCH AND NOT name MATCHES "${MATCH}")
      continue()
    endif()
    list(FIND seen "${name}" at)
    if(at EQUAL -1)
      list(APPEND seen "${name}")
      string(APPEND map "${name} ${PREFIX}${name}\n")
    endif()
  endif()
endforeach()
if(map STREQUAL "")
  message(FATAL_ERROR "prefix_symbols.cmake: no symbol to rename in ${INPUT}")
endif()
file(WRITE ${OUTPUT}.map "${map}")
execute_process(COMMAND ${OBJCOPY} --redefine-syms=${OUTPUT}.map ${INPUT} ${OUTPUT} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "prefix_symbols.cmake: ${OBJCOPY} failed on ${INPUT}")
endif()
