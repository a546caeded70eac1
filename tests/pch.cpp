// The source of immerse_test_pch, whose precompiled headers the test programs reuse (tests/CMakeLists.txt).
