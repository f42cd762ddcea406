# Sanitizer and fuzzing builds (docs/robustness.md).
#
# SDFCSG_SANITIZE is handed to -fsanitize= for every target of the build (library, tool, tests),
# e.g. "address,undefined". Nothing recovers: the first report ends the program, so a test that
# trips a sanitizer fails. SDFCSG_FUZZ builds the libFuzzer targets in tests/fuzz; libFuzzer
# ships with clang only, and without SDFCSG_SANITIZE the fuzz build uses address,undefined.
set(SDFCSG_SANITIZE "" CACHE STRING "Sanitizers for every target, e.g. address,undefined")
option(SDFCSG_FUZZ "Build the libFuzzer targets in tests/fuzz (needs clang)" OFF)

set(SDFCSG_SANITIZERS "${SDFCSG_SANITIZE}")
if(SDFCSG_FUZZ)
    if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
        message(FATAL_ERROR "SDFCSG_FUZZ needs clang for libFuzzer; configure with "
                            "-DCMAKE_CXX_COMPILER=clang++-14 (or another clang)")
    endif()
    if(NOT SDFCSG_SANITIZERS)
        set(SDFCSG_SANITIZERS address,undefined)
    endif()
endif()

if(SDFCSG_SANITIZERS)
    # Frame pointers and line tables (-g1: no more, which keeps the build short) make the
    # reports readable.
    add_compile_options(-fsanitize=${SDFCSG_SANITIZERS} -fno-sanitize-recover=all
                        -fno-omit-frame-pointer -g1)
    add_link_options(-fsanitize=${SDFCSG_SANITIZERS})
    # UBSan's vptr check needs the typeinfo of every polymorphic class it meets, and Debian builds
    # glslang without RTTI (the shader compiler derives from and deletes glslang's classes).
    if(SDFCSG_SANITIZERS MATCHES "undefined")
        add_compile_options(-fno-sanitize=vptr)
    endif()
endif()
if(SDFCSG_FUZZ)
    # Coverage feedback from every target; only the fuzz targets link libFuzzer's main.
    add_compile_options(-fsanitize=fuzzer-no-link)
endif()

# What the tests' environment adds under the sanitizers (appended to each test's ENVIRONMENT,
# hence the leading ';'): the leak suppressions for lavapipe, whose driver is preloaded so that
# the Vulkan loader's unloading it does not leave its leaks unnamed (tests/sanitizers/lsan.supp);
# a factor for the command-line tests' deadlines (Ctrl-C within a second), since the leak check at
# exit scans the whole heap, hundreds of megabytes after a large mesh; and 3 seeds for each seeded
# mesh property test (SDFCSG_MESH_SEEDS): the sanitizers look for memory and undefined-behaviour
# errors along code paths that 3 random scenes take as well as 40, and the release suite runs
# every seed (40 scenes of many small primitives took 139 s of the sanitized suite's time); and
# SDFCSG_SANITIZED, by which tests that repeat one code path over costly cases run a few (the
# offsets' baking, ten times slower under the sanitizers, bakes 2 of its 5 children).
set(SDFCSG_SANITIZER_ENV "")
if(SDFCSG_SANITIZERS)
    find_library(SDFCSG_LAVAPIPE_LIBRARY vulkan_lvp)
    set(SDFCSG_SANITIZER_ENV ";LSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/tests/sanitizers/lsan.supp:print_suppressions=0;UBSAN_OPTIONS=print_stacktrace=1;SDFCSG_TEST_DEADLINE_SCALE=3;SDFCSG_MESH_SEEDS=3;SDFCSG_SANITIZED=1")
    if(SDFCSG_LAVAPIPE_LIBRARY)
        # The preloaded driver precedes the sanitizer runtime in the library list.
        string(APPEND SDFCSG_SANITIZER_ENV
               ";LD_PRELOAD=${SDFCSG_LAVAPIPE_LIBRARY};ASAN_OPTIONS=verify_asan_link_order=0")
    endif()
endif()
