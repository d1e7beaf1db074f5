// An empty program linked against one library target and nothing else: the shared
// libraries its link line names (with --no-as-needed, every one of them) are what that
// library pulls in. tests/link/check_link_boundaries.sh reads them.
int main() { return 0; }
