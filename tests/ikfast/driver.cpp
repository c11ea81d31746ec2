/* Test driver for a derive-ik IKFast shim: per pose on stdin (12 doubles: eerot row-major,
   then eetrans; then the free values, GetNumFreeParameters() of them), writes an int32 count
   and DOF doubles per solution; `info` prints the interface functions' answers. */
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include SHIM

int main(int argc, char **argv)
{
    const int dof = GetNumJoints(), nfree = GetNumFreeParameters();
    if (argc > 1 && std::strcmp(argv[1], "info") == 0) {
        std::printf("%d %d %d 0x%x %s %s", dof, nfree, GetIkRealSize(), GetIkType(),
                    GetIkFastVersion(), GetKinematicsHash());
        for (int k = 0; k < nfree; k++) {
            std::printf(" %d", GetFreeParameters()[k]);
        }
        std::printf("\n");
        return 0;
    }
    double in[12], pfree[8], q[16], trans[3], rot[9];
    while (std::fread(in, sizeof(double), 12, stdin) == 12) {
        if (nfree && std::fread(pfree, sizeof(double), nfree, stdin) != (size_t)nfree) {
            return 2;
        }
        ikfast::IkSolutionList<double> list;
        const bool ok = ComputeIk(in + 9, in, nfree ? pfree : NULL, list);
        const int32_t count = (int32_t)list.GetNumSolutions();
        if (ok != (count > 0)) {
            return 3;
        }
        std::fwrite(&count, sizeof count, 1, stdout);
        for (int32_t k = 0; k < count; k++) {
            for (int j = 0; j < dof; j++) {
                q[j] = list.values[k][j];
            }
            ComputeFk(q, trans, rot); /* a round trip through ComputeFk, checked by the test */
            std::fwrite(q, sizeof(double), dof, stdout);
            std::fwrite(rot, sizeof(double), 9, stdout);
            std::fwrite(trans, sizeof(double), 3, stdout);
        }
    }
    return 0;
}
