// The one source of hil_test_pch: the target exists to compile the test
// programs' precompiled header (tests/CMakeLists.txt).
