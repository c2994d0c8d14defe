# both_dimensions.cmake - one library for both dimensions out of the DIM = 2 and DIM = 3 builds of
# the library (docs/development.md, "Dimensions"): the 3D build's every defined global symbol gets
# the prefix dim3_, the 2D build's public API (mixsph_*) the prefix dim2_, and the dispatcher
# lib/src/sim_dimension.c defines the public API, forwarding each simulation to the build of its
# case's "dimensions". The 2D build's code is the 2D library's, byte for byte: only names change.
#
#   mixsph_both_dimensions(<target> <2D library target> <3D library target>)
#
# <target> is a static library (the dispatcher) whose link interface holds both renamed archives;
# the caller adds what both builds link (cJSON, HDF5, OpenMP, threads) to <target>.
#
#   mixsph_dim3_executable(<executable> <both-dimensions target> <source>)
#
# An executable compiled at DIM = 3 against the library's internal headers (a DIM = 3 test) that
# links <target>'s 3D build: its object is renamed with the 3D archive's map, so its calls reach
# the dim3_ symbols. The DIM = 3 tests need no third build of the library.
set(MIXSPH_PREFIX_SYMBOLS ${CMAKE_CURRENT_LIST_DIR}/prefix_symbols.cmake)

function(mixsph_both_dimensions target lib2 lib3)
  if(NOT CMAKE_NM OR NOT CMAKE_OBJCOPY)
    message(FATAL_ERROR "mixsph_both_dimensions: the toolchain's nm and objcopy were not found")
  endif()
  set(out2 ${CMAKE_CURRENT_BINARY_DIR}/${CMAKE_STATIC_LIBRARY_PREFIX}${target}_renamed_dim2${CMAKE_STATIC_LIBRARY_SUFFIX})
  set(out3 ${CMAKE_CURRENT_BINARY_DIR}/${CMAKE_STATIC_LIBRARY_PREFIX}${target}_renamed_dim3${CMAKE_STATIC_LIBRARY_SUFFIX})
  add_custom_command(OUTPUT ${out2}
    COMMAND ${CMAKE_COMMAND} -DNM=${CMAKE_NM} -DOBJCOPY=${CMAKE_OBJCOPY} -DINPUT=$<TARGET_FILE:${lib2}>
            -DOUTPUT=${out2} -DPREFIX=dim2_ -DMATCH=^mixsph_ -P ${MIXSPH_PREFIX_SYMBOLS}
    DEPENDS ${lib2} ${MIXSPH_PREFIX_SYMBOLS}
    COMMENT "The 2D build's public API as dim2_mixsph_* (${target})" VERBATIM)
  add_custom_command(OUTPUT ${out3} ${out3}.map
    COMMAND ${CMAKE_COMMAND} -DNM=${CMAKE_NM} -DOBJCOPY=${CMAKE_OBJCOPY} -DINPUT=$<TARGET_FILE:${lib3}>
            -DOUTPUT=${out3} -DPREFIX=dim3_ -P ${MIXSPH_PREFIX_SYMBOLS}
    DEPENDS ${lib3} ${MIXSPH_PREFIX_SYMBOLS}
    COMMENT "The 3D build's symbols as dim3_* (${target})" VERBATIM)
  add_custom_target(${target}_archives DEPENDS ${out2} ${out3})
  add_library(${target} STATIC ${PROJECT_SOURCE_DIR}/lib/src/sim_dimension.c)
  add_dependencies(${target} ${target}_archives)
  target_include_directories(${target} PUBLIC ${PROJECT_SOURCE_DIR}/lib/include PRIVATE ${MIXSPH_INTERNAL_INCLUDES})
  # the dispatcher's own code is the 2D build's (it calls its state and checkpoint readers)
  target_compile_definitions(${target} PRIVATE MIXSPH_DIM=2)
  target_link_libraries(${target} PUBLIC ${out2} ${out3})
  set_target_properties(${target} PROPERTIES MIXSPH_DIM3_SYMBOL_MAP ${out3}.map)
endfunction()

function(mixsph_dim3_executable name dims source)
  get_target_property(map ${dims} MIXSPH_DIM3_SYMBOL_MAP)
  add_library(${name}_objects OBJECT ${source})
  target_include_directories(${name}_objects PRIVATE ${PROJECT_SOURCE_DIR}/lib/include ${MIXSPH_INTERNAL_INCLUDES})
  target_compile_definitions(${name}_objects PRIVATE MIXSPH_DIM=3)
  # as the library's: the same OpenMP flags (simd pragmas of the internal headers)
  if(MIXSPH_OPENMP)
    target_link_libraries(${name}_objects PRIVATE OpenMP::OpenMP_C)
  endif()
  set(renamed ${CMAKE_CURRENT_BINARY_DIR}/${name}_renamed_dim3${CMAKE_C_OUTPUT_EXTENSION})
  add_custom_command(OUTPUT ${renamed}
    COMMAND ${CMAKE_COMMAND} -DOBJCOPY=${CMAKE_OBJCOPY} -DINPUT=$<TARGET_OBJECTS:${name}_objects>
            -DOUTPUT=${renamed} -DMAP=${map} -P ${MIXSPH_PREFIX_SYMBOLS}
    DEPENDS ${name}_objects $<TARGET_OBJECTS:${name}_objects> ${map} ${MIXSPH_PREFIX_SYMBOLS}
    COMMENT "${name}: its calls to the 3D build as dim3_*" VERBATIM)
  add_executable(${name} ${renamed})
  set_target_properties(${name} PROPERTIES LINKER_LANGUAGE C)
  add_dependencies(${name} ${dims}_archives)
  target_link_libraries(${name} PRIVATE ${dims})
endfunction()
