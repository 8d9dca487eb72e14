// The source of the tests' precompiled header (tests/CMakeLists.txt, sv_test_pch): nothing of its
// own; the header is what CMake precompiles beside it.
