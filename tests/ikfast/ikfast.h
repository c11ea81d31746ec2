/* Test-only stand-in for the ikfast.h that MoveIt's IKFast plugin brings (interface version
   61): only the declarations derive-ik's shim uses, with the same names and signatures, and
   the small solution list the test driver needs. Not shipped; not a copy of ikfast.h. */
#ifndef DERIVE_IK_TEST_IKFAST_H
#define DERIVE_IK_TEST_IKFAST_H

#include <cstddef>
#include <vector>

#define IKFAST_API extern "C"

namespace ikfast {

template <typename T> struct IkSingleDOFSolutionBase {
    IkSingleDOFSolutionBase() : fmul(0), foffset(0), freeind(-1), maxsolutions(1) {}
    T fmul, foffset;
    signed char freeind;
    unsigned char jointtype;
    unsigned char maxsolutions;
    unsigned char indices[5];
};

template <typename T> class IkSolutionListBase {
public:
    virtual ~IkSolutionListBase() {}
    virtual size_t AddSolution(const std::vector<IkSingleDOFSolutionBase<T> > &vinfos,
                               const std::vector<int> &vfree) = 0;
    virtual size_t GetNumSolutions() const = 0;
    virtual void Clear() = 0;
};

/* the test's list: each solution's joint values (offset + multiplier * free value) */
template <typename T> class IkSolutionList : public IkSolutionListBase<T> {
public:
    size_t AddSolution(const std::vector<IkSingleDOFSolutionBase<T> > &vinfos,
                       const std::vector<int> &vfree)
    {
        std::vector<T> q;
        for (size_t j = 0; j < vinfos.size(); j++) {
            q.push_back(vinfos[j].foffset);
        }
        (void)vfree;
        values.push_back(q);
        return values.size() - 1;
    }
    size_t GetNumSolutions() const { return values.size(); }
    void Clear() { values.clear(); }
    std::vector<std::vector<T> > values;
};

}  // namespace ikfast

#endif
