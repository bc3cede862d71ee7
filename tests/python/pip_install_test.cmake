# `pip install ./python` as a Python team does it, in a fresh venv that sees
# the system's pytest, then the tests of tests/python with the plugin found
# through its pytest11 entry point (no -p, no PYTHONPATH).
#
# cmake -DPYTHON=... -DPACKAGE_DIR=... -DTESTS_DIR=... -DWORK_DIR=... -P pip_install_test.cmake
foreach(var PYTHON PACKAGE_DIR TESTS_DIR WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "pip_install_test.cmake: -D${var}=... is required")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code)
  if(NOT code EQUAL 0)
    list(JOIN ARGN " " command)
    message(FATAL_ERROR "failed (${code}): ${command}")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
# A copy of the package, so the build leaves nothing in the source tree.
file(COPY ${PACKAGE_DIR}/ DESTINATION ${WORK_DIR}/src
     PATTERN "__pycache__" EXCLUDE PATTERN "build" EXCLUDE PATTERN "*.egg-info" EXCLUDE)
set(venv ${WORK_DIR}/venv)
run(${PYTHON} -m venv --system-site-packages ${venv})
run(${venv}/bin/python -m pip install --no-index --no-build-isolation --no-cache-dir
    --disable-pip-version-check -q ${WORK_DIR}/src)

# The installed copy is the one imported, and pytest lists its option.
unset(ENV{PYTHONPATH})
execute_process(COMMAND ${venv}/bin/python -c "import hil_pytest; print(hil_pytest.__file__)"
                OUTPUT_VARIABLE where OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE code)
if(NOT code EQUAL 0 OR NOT where MATCHES "^${venv}/")
  message(FATAL_ERROR "hil_pytest is imported from '${where}', not from the venv ${venv}")
endif()
message(STATUS "hil_pytest installed at ${where}")
execute_process(COMMAND ${venv}/bin/python -m pytest -p no:cacheprovider --help
                OUTPUT_VARIABLE help RESULT_VARIABLE code)
if(NOT code EQUAL 0 OR NOT help MATCHES "--hil-binary")
  message(FATAL_ERROR "pytest in the venv does not list --hil-binary: the pytest11 entry point was not found")
endif()

# The fixtures' own tests: the rest of tests/python runs in python/fixtures.
run(${venv}/bin/python -m pytest -p no:cacheprovider -v -rs --basetemp=${WORK_DIR}/tmp
    ${TESTS_DIR}/test_fixtures.py)
