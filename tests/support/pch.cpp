// The holder of the tests' shared precompiled header (tests/CMakeLists.txt, MFSI_PCH): an
// executable, so the header is compiled with an executable's options, as every test source is.
// It defines nothing; its main() is mfsi_test_support's.
