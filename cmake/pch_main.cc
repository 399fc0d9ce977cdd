// The program that makes the test programs' precompiled header (RECRUIT_PCH_TESTS,
// tests/CMakeLists.txt); it does nothing.
int main() { return 0; }
