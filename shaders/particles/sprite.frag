#version 460
// Particle sprites into the WBOIT targets: opacity and normal map from the sprite texture, the
// emitter's additiveness per particle (fire 1, smoke 0), and for lit sprites the lighting from
// the atlas (bilinear inside the sprite's rectangle), per pixel, or per vertex.
#include "particles/particles.glsl"
#include "oit/wboit.glsl"

layout(early_fragment_tests) in;
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t particleFrame;
} pc;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec2 inUv;
layout(location = 2) flat in uint inParticle;
layout(location = 3) in vec3 inVertexLight;
layout(location = 4) flat in uvec4 inAtlasRect;

layout(location = 0) out vec4 outAccum;
layout(location = 1) out vec4 outReveal;

// Bilinear inside the sprite's rectangle: texel centres sit at (k + 0.5) / side, and clamping to
// the outer centres keeps the taps off the neighbours' texels.
vec3 atlasLighting(ParticleFrame pf, uvec4 rect, vec2 uv) {
    vec2 texel = clamp(uv * float(rect.z), vec2(0.5), vec2(float(rect.z) - 0.5)) + vec2(rect.xy);
    return sampleTextureLod(pf.atlasReadSlot, SAMPLER_LINEAR_CLAMP, texel / float(pf.atlasSize), 0.0).rgb;
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ParticleFrame pf = ParticleFrameRef(pc.particleFrame).p;
    GpuParticle p = ParticleBuffer(pf.particles).p[inParticle];
    GpuParticleEmitter e = ParticleEmitterBuffer(pf.emitters).e[p.emitter];
    vec4 color = particleColor(e, p);
    // Half resolution: this fragment covers a 2x2 block of full-resolution pixels; it counts for
    // the fraction of them whose opaque surface lies behind it (reversed Z: larger is nearer).
    float visible = 1.0;
    if (pf.halfRes != 0u) {
        ivec2 size = textureSize(gTextures[pf.depthReadSlot], 0);
        ivec2 base = ivec2(gl_FragCoord.xy) * 2;
        visible = 0.0;
        for (int k = 0; k < 4; ++k) {
            ivec2 q = min(base + ivec2(k & 1, k >> 1), size - 1);
            visible += gl_FragCoord.z >= fetchTextureUniform(pf.depthReadSlot, q, 0).r ? 0.25 : 0.0;
        }
        if (visible == 0.0) discard;
    }
    uint seed = particleSpriteSeed(e, inParticle, p);
    vec3 shaded = color.rgb; // unlit: emission
    if ((e.flags & PARTICLE_EMITTER_LIT) != 0u) {
        vec3 light = vec3(-1.0);
        if (pf.lighting == PARTICLE_LIGHTING_ATLAS && inAtlasRect.w != 0u)
            light = atlasLighting(pf, inAtlasRect, inUv);
        else if (pf.lighting == PARTICLE_LIGHTING_VERTEX)
            light = inVertexLight;
        if (light.r < 0.0) // per pixel (and atlas sprites that found no room)
            light = shadeParticle(f, inPosition,
                                  particleWorldNormal(particleBasis(f, p),
                                                      particleSpriteNormal(inUv, seed, e.normalScale)),
                                  e.wrap);
        shaded *= light;
    }
    TransparentFragment t =
        transparentFragment(shaded, particleSpriteOpacity(inUv, seed) * color.a * visible,
                            e.additiveness);
    wboitOutputs(t, viewDepthOf(f, inPosition), outAccum, outReveal);
}
