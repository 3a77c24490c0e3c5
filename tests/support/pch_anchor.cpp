// Anchor of the tests' precompiled header (tests/CMakeLists.txt): compiles nothing of its own.
