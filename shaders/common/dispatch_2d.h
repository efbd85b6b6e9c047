// Workgroup counts past what one dispatch dimension is sure to hold (every device allows
// 65535 groups in x): n groups as x * y with y = ceil(n / 65535) and x = ceil(n / y), rows of
// nearly equal length, at most y - 1 groups past the end. Written once for C++ (vkCmdDispatch
// sizes) and GLSL (indirect arguments built on the GPU, and a group's index).
// Why rows of equal length: this was x = min(n, 32768), y = ceil(n / 32768), and lavapipe
// splits a dispatch's groups, in order, into one contiguous range per thread (its compute
// thread pool's iter_per_thread), so builtin:lights at 1920x1080 (35,554 queued chunks: a full
// row, then a row of 2,786 chunks and 29,982 groups that return at once) ran the first row on
// one thread and little on the other: the all-features shadel shading took 1046 ms, and 587 ms as
// 17,777 x 2 groups, the image the same. (The groups that return cost little: a variant
// returning every group at that check took 47 ms.) builtin:default at 1920x1080 on the orbit
// (40,950 chunks) had the same: decoupled / forward 2.495 -> 1.876 (bench, 12 frames, 2 rounds).
#ifndef SHADEL_DISPATCH_2D_H
#define SHADEL_DISPATCH_2D_H

#ifdef __cplusplus
#include <cstdint>
#ifndef SHADEL_INLINE
#define SHADEL_INLINE inline
#endif
namespace shadel::shader {
using uint = uint32_t;
struct Dispatch2d {
    uint x, y;
};
SHADEL_INLINE Dispatch2d dispatch2d(uint n) {
    uint y = (n + 65534u) / 65535u;
    return {y == 0u ? 0u : (n + y - 1u) / y, y};
}
} // namespace shadel::shader
#else
// (x, y) of n groups; (0, 0) for none.
uvec2 dispatch2d(uint n) {
    uint y = (n + 65534u) / 65535u;
    return uvec2(y == 0u ? 0u : (n + y - 1u) / y, y);
}
// This group's index in a dispatch2d dispatch (the caller skips indices >= n).
uint dispatch2dGroup() {
    return gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
}
#endif

#endif
