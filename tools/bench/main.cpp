// placeholder: the benchmark is implemented in a later commit
int main() { return 0; }
