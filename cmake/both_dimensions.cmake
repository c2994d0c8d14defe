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
  add_custom_command(OUTPUT ${out3}
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
endfunction()
