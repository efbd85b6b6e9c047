// Maps a thread index over all blocks of this frame's rects to its rect and sheet block.
#ifndef SHADEL_RECTS_GLSL
#define SHADEL_RECTS_GLSL
uint rectBlock(ShadelFrame s, uint t, out GpuShadelRect rect, out uint rectIndex) {
    ShadelRectBuffer rects = ShadelRectBuffer(s.rects);
    // Binary search: the last rect whose firstBlock <= t.
    uint lo = 0u, hi = s.rectCount - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) / 2u;
        if (rects.r[mid].firstBlock <= t) lo = mid; else hi = mid - 1u;
    }
    rect = rects.r[lo];
    rectIndex = lo;
    uint local = t - rect.firstBlock;
    uvec2 b = rect.rect.xy + uvec2(local % rect.rect.z, local / rect.rect.z);
    return b.y * s.sheetBlocks + b.x;
}

uint rectBlock(ShadelFrame s, uint t, out GpuShadelRect rect) {
    uint rectIndex;
    return rectBlock(s, t, rect, rectIndex);
}
#endif
