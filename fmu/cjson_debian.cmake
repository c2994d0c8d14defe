# fmu/cjson_debian.cmake - cJSON as a static library for the FMU's binaries, built from Debian's
# source package of cJSON (the upstream tarball and Debian's patches, security fixes included).
#
# Why: the FMU's binaries must carry what they need (docs/fmu.md, "What the binaries need"), and
# Debian's libcjson-dev ships only the shared library; the Windows binary has no Debian cJSON at
# all. cJSON is one C file: it is compiled into the FMU for every platform from the same source.
#
# The source is the version of Debian 12's libcjson-dev (the headers the rest of mixsph compiles
# against), downloaded once per build tree from Debian's archive and checked against the SHA-256
# sums of its .dsc, then patched with Debian's patch series. A machine that cannot reach the
# archive can pass -DMIXSPH_CJSON_SOURCE_DIR=<an unpacked, patched cJSON-1.7.15>.
#
# Defines the target cjson_static (include it as <cjson/cJSON.h>, as the library does) and the
# cache variable MIXSPH_CJSON_SOURCE_DIR (handed on to the cross build).

set(_cjson_version 1.7.15)
set(_cjson_debian_version 1.7.15-1+deb12u4)
set(_cjson_files
    "cjson_${_cjson_version}.orig.tar.gz|5308fd4bd90cef7aa060558514de6a1a4a0819974a26e6ed13973c5f624c24b2|268593a0838a6ae9115ec778828f1e06a88def03"
    "cjson_${_cjson_debian_version}.debian.tar.xz|afd19a970966cf534ff1e9ec077d710a5e7e78eb4ec9b499c8bdc32e55da12cb|cf12d9b80556be5c4d77bfc711d669a34901ad29")

set(MIXSPH_CJSON_SOURCE_DIR "" CACHE PATH
    "An unpacked and patched cJSON ${_cjson_version} source tree (empty: download Debian's source package)")

if(NOT MIXSPH_CJSON_SOURCE_DIR)
  set(_dir ${CMAKE_BINARY_DIR}/_deps/cjson-debian)
  set(_src ${_dir}/cJSON-${_cjson_version})
  if(NOT EXISTS ${_src}/.patched)
    file(REMOVE_RECURSE ${_src} ${_dir}/debian)
    foreach(_entry IN LISTS _cjson_files)
      string(REPLACE "|" ";" _entry "${_entry}")
      list(GET _entry 0 _name)
      list(GET _entry 1 _sha256)
      list(GET _entry 2 _sha1)
      if(NOT EXISTS ${_dir}/${_name})
        message(STATUS "cJSON for the FMU: downloading Debian's ${_name}")
        # the pool holds the current version; snapshot.debian.org every version by its SHA-1
        foreach(_url "http://deb.debian.org/debian/pool/main/c/cjson/${_name}"
                     "https://snapshot.debian.org/file/${_sha1}")
          file(DOWNLOAD ${_url} ${_dir}/${_name}.part EXPECTED_HASH SHA256=${_sha256} STATUS _st TIMEOUT 120)
          list(GET _st 0 _code)
          if(_code EQUAL 0)
            file(RENAME ${_dir}/${_name}.part ${_dir}/${_name})
            break()
          endif()
          file(REMOVE ${_dir}/${_name}.part)
          message(STATUS "cJSON for the FMU: ${_url}: ${_st}")
        endforeach()
      endif()
      if(NOT EXISTS ${_dir}/${_name})
        message(FATAL_ERROR "cJSON for the FMU: cannot download Debian's ${_name} (see above). Pass "
                            "-DMIXSPH_CJSON_SOURCE_DIR=<unpacked and patched cJSON-${_cjson_version}>.")
      endif()
      file(ARCHIVE_EXTRACT INPUT ${_dir}/${_name} DESTINATION ${_dir})
    endforeach()
    find_program(MIXSPH_PATCH patch REQUIRED)
    file(STRINGS ${_dir}/debian/patches/series _series REGEX "^[^#]")
    foreach(_p IN LISTS _series)
      execute_process(COMMAND ${MIXSPH_PATCH} -p1 --batch --quiet -i ${_dir}/debian/patches/${_p}
                      WORKING_DIRECTORY ${_src} RESULT_VARIABLE _rc)
      if(NOT _rc EQUAL 0)
        message(FATAL_ERROR "cJSON for the FMU: Debian's patch ${_p} does not apply")
      endif()
    endforeach()
    file(TOUCH ${_src}/.patched)
    message(STATUS "cJSON for the FMU: Debian's cjson ${_cjson_debian_version} in ${_src}")
  endif()
  set(MIXSPH_CJSON_SOURCE_DIR ${_src} CACHE PATH "" FORCE)
endif()

# <cjson/cJSON.h>, as Debian installs it and the library includes it
configure_file(${MIXSPH_CJSON_SOURCE_DIR}/cJSON.h ${CMAKE_BINARY_DIR}/_deps/cjson-include/cjson/cJSON.h COPYONLY)
add_library(cjson_static STATIC ${MIXSPH_CJSON_SOURCE_DIR}/cJSON.c)
target_include_directories(cjson_static SYSTEM PUBLIC ${CMAKE_BINARY_DIR}/_deps/cjson-include)
target_compile_options(cjson_static PRIVATE -w) # third-party code: its warnings are not ours to fix
# Its functions stay inside the FMU's binary (cJSON.h would otherwise mark them dllexport on Windows)
target_compile_definitions(cjson_static PUBLIC CJSON_HIDE_SYMBOLS)
