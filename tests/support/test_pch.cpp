// The unit the tests' precompiled header is built with (tests/CMakeLists.txt,
// cstab_test_pch); it has no code of its own.
