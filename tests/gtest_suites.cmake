# Read by ctest, through the include file that tests/CMakeLists.txt generates: registers one
# ctest test per GoogleTest suite of a test program, where gtest_discover_tests would register
# one per case. Every GPU test process makes a Vulkan context with the validation layer, which
# costs about as much as a typical GPU test; a suite's cases share one.
#
# A suite becomes the test SUITE, running PROGRAM --gtest_filter=SUITE.*; one with more GPU cases
# than kCasesPerPart is cut into parts SUITE-1ofN ... SUITE-NofN (GoogleTest's sharding), so the
# two cores of `ctest -j2` stay busy to the end. Failures name their cases in the test's output.
# Labels: `gpu` for suites whose fixture uses the device (the program includes gpu_test.h and the
# suite is not a plain TEST()), `unit` for the others.
#
# The listing is cached next to the program and made again when the program is rebuilt.

set(kCasesPerPart 10)

# PROGRAM: the test executable; SOURCE: its .cpp; LISTING: the file to cache the tests in.
# Reads SDFCSG_TEST_ENVIRONMENT (the list of VAR=value every test gets).
function(sdfcsg_add_gtest_suites program source listing)
    get_filename_component(name "${program}" NAME)
    if(NOT EXISTS "${program}")
        add_test("${name}_NOT_BUILT" "${name}_NOT_BUILT")
        return()
    endif()
    if(EXISTS "${listing}" AND "${listing}" IS_NEWER_THAN "${program}"
        AND "${listing}" IS_NEWER_THAN "${CMAKE_CURRENT_LIST_FILE}"
        AND "${listing}" IS_NEWER_THAN "${CMAKE_CURRENT_FUNCTION_LIST_FILE}")
        include("${listing}")
        return()
    endif()

    get_filename_component(directory "${program}" DIRECTORY)
    execute_process(COMMAND "${program}" --gtest_list_tests WORKING_DIRECTORY "${directory}"
        TIMEOUT 60 OUTPUT_VARIABLE output RESULT_VARIABLE result)
    if(NOT result EQUAL 0)
        message(FATAL_ERROR "${program} --gtest_list_tests failed (${result}):\n${output}")
    endif()

    # Suites whose every case is a plain TEST() get no fixture, so no device. A program whose
    # CPU suites take minutes says so in a line `// ctest cost N`, N their COST (see below).
    set(gpu_program FALSE)
    set(plain_suites "")
    set(program_cost 0)
    file(STRINGS "${source}" lines
        REGEX "^#include \"gpu_test\\.h\"|^TEST\\(|^// ctest cost [0-9]+")
    foreach(line IN LISTS lines)
        if(line MATCHES "^#include")
            set(gpu_program TRUE)
        elseif(line MATCHES "^TEST\\(([A-Za-z0-9_]+),")
            list(APPEND plain_suites "${CMAKE_MATCH_1}")
        elseif(line MATCHES "^// ctest cost ([0-9]+)")
            set(program_cost ${CMAKE_MATCH_1})
        endif()
    endforeach()

    # Suite lines end in '.', case lines are indented; parameters after '#' may hold anything,
    # and only the cases' count is needed from them.
    string(REGEX REPLACE "[][;]" "_" output "${output}")
    string(REPLACE "\n" ";" output "${output}")
    set(suites "")
    foreach(line IN LISTS output)
        if(line MATCHES "^([^ ]+)\\.( +#.*)?$")
            set(suite "${CMAKE_MATCH_1}")
            list(APPEND suites "${suite}")
            set(cases_${suite} 0)
        elseif(line MATCHES "^  [^ ]" AND DEFINED suite)
            math(EXPR cases_${suite} "${cases_${suite}} + 1")
        endif()
    endforeach()

    # A test counts as skipped only if every case of it was skipped and none failed: GoogleTest
    # then ends its output with the list of skipped cases.
    string(CONCAT all_skipped [["\\[  PASSED  \\] 0 tests\\.\n]]
        [[\\[  SKIPPED \\] [0-9]+ tests?, listed below:\n(\\[  SKIPPED \\] [^\n]*\n)+$"]])
    set(script "")
    foreach(suite IN LISTS suites)
        set(cases ${cases_${suite}})
        string(REGEX REPLACE "^.*/" "" fixture "${suite}")
        list(FIND plain_suites "${fixture}" plain)
        set(parts 1)
        set(label unit)
        if(gpu_program AND plain EQUAL -1)
            set(label gpu)
            math(EXPR parts "(${cases} + ${kCasesPerPart} - 1) / ${kCasesPerPart}")
        endif()
        foreach(part RANGE 1 ${parts})
            set(test "${suite}")
            set(environment "${SDFCSG_TEST_ENVIRONMENT}")
            # Without measured times (a first run), ctest starts the tests of highest COST
            # first: GPU suites by their count of cases, the quick CPU suites last, and slow
            # ones by their program's cost line (a slow suite started last ends the run alone).
            set(cost ${program_cost})
            if(label STREQUAL "gpu")
                math(EXPR cost "${cases} / ${parts}")
            endif()
            if(parts GREATER 1)
                set(test "${suite}-${part}of${parts}")
                math(EXPR index "${part} - 1")
                list(APPEND environment GTEST_TOTAL_SHARDS=${parts} GTEST_SHARD_INDEX=${index})
            endif()
            string(APPEND script
                "add_test([==[${test}]==] [==[${program}]==] [==[--gtest_filter=${suite}.*]==])\n"
                "set_tests_properties([==[${test}]==] PROPERTIES LABELS ${label} COST ${cost}\n"
                "    WORKING_DIRECTORY [==[${directory}]==]\n"
                "    ENVIRONMENT [==[${environment}]==]\n"
                "    SKIP_REGULAR_EXPRESSION ${all_skipped})\n")
            if(suite MATCHES "^DISABLED_|/DISABLED_")
                string(APPEND script
                    "set_tests_properties([==[${test}]==] PROPERTIES DISABLED TRUE)\n")
            endif()
        endforeach()
    endforeach()
    file(WRITE "${listing}" "${script}")
    include("${listing}")
endfunction()
