#include <cstdio>
int main() { std::puts("mfsi"); return 0; }
