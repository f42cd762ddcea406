# Installs the built engine into a private prefix, builds tests/consumer/project against it
# with find_package(sdfcsg), runs the result and checks the PNGs it writes (of a scene file, and
# of a scene built in code with sdfcsg/model.h).
# Inputs: BUILD_DIR, SOURCE_DIR, WORK_DIR, GENERATOR, CXX, and SANITIZERS when the library was
# built with them (the consumer then links their runtimes, with the same compiler).
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
    execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "failed (${rc}): ${ARGV}")
    endif()
endfunction()
set(sanitizer_args "")
if(SANITIZERS)
    set(sanitizer_args -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=${SANITIZERS})
endif()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/consumer/project -B ${WORK_DIR}/build -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix ${sanitizer_args})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/consumer ${SOURCE_DIR}/assets/scenes/csg_part.json ${WORK_DIR}/out.png
    ${WORK_DIR}/modelled.png)
foreach(png IN ITEMS out.png modelled.png)
    file(READ ${WORK_DIR}/${png} header LIMIT 8 HEX)
    if(NOT header STREQUAL "89504e470d0a1a0a")
        message(FATAL_ERROR "the consumer did not write ${png}")
    endif()
endforeach()
