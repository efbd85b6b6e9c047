// Texture streaming feedback (render/streaming, GPU priorities): every material
// texture sample reports the finest MIP it wanted, per bindless slot, atomically min-reduced into
// a small buffer the CPU reads after the frame. The MIP is that of a virtual 32768^2 texture, so
// it does not depend on how much of the texture is resident: the CPU turns it into the side the
// texture needs (32768 >> mip). Forward shading reports per pixel, decoupled shading per shadel
// (its derivatives are the shadel footprint), so each path asks for exactly what it samples.
#ifndef SHADEL_STREAMING_FEEDBACK_GLSL
#define SHADEL_STREAMING_FEEDBACK_GLSL

#define TEXTURE_FEEDBACK_LOG2_SIZE 15.0

// FrameConstants.textureFeedback, set by the shading entry points; 0 = no streaming.
uint64_t gTextureFeedback = 0ul;

void recordTextureFeedback(uint slot, vec2 dx, vec2 dy) {
    if (gTextureFeedback == 0ul || slot == NO_TEXTURE) return;
    float footprint = max(length(dx), length(dy)); // uv units per pixel (or shadel)
    // The finer of the two levels trilinear filtering reads.
    float lod = floor(TEXTURE_FEEDBACK_LOG2_SIZE + log2(max(footprint, 1e-12)));
    uint mip = uint(clamp(lod, 0.0, TEXTURE_FEEDBACK_LOG2_SIZE));
    UintBuffer wanted = UintBuffer(gTextureFeedback);
    if (wanted.v[slot] > mip) atomicMin(wanted.v[slot], mip); // most samples skip the atomic
}
#endif
