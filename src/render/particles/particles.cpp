#include "render/particles/particles.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/error.h"
#include "core/log.h"
#include "particles/particle_types.h"
#include "render/forward/forward_passes.h"
#include "render/oit/oit.h"
#include "rhi/rendering.h"

namespace shadel {

namespace {
constexpr float kStepSeconds = 1.0f / 60.0f; // one simulation step per frame
}

struct ParticleState {
    uint32_t particleCount = 0;
    float maxLifetime = 0.0f;
    uint32_t stepsTaken = 0; // simulation steps before this frame
    uint32_t stepsThisFrame = 0;
    BufferHandle particles;   // gpu::GpuParticle[], simulated in place
    BufferHandle emitters;    // gpu::GpuParticleEmitter[]
    BufferHandle atlasCounts; // gpu::ParticleAtlasCounts, read back after the frame
    BufferHandle frame;       // gpu::ParticleFrame (host-visible)
    TextureHandle atlas;      // RGBA16F lighting at unit albedo
    TextureWriteView atlasWrite;
    TextureReadView atlasRead;
    Pipeline simulate, atlasLight, sprites, atlasView;
    // --particle-resolution half: the sprites' own WBOIT targets at half resolution, drawn
    // without a depth attachment (each fragment tests the 2x2 full-resolution depths itself).
    uint32_t halfWidth = 0, halfHeight = 0;
    TextureHandle accumHalf, revealHalf;
    RenderTargetView accumHalfTarget, revealHalfTarget;
    TextureReadView accumHalfRead, revealHalfRead;
    Pipeline spritesHalf;
    Pipeline meshes; // opaque mesh particles, forward
    bool hasMeshes = false;
};

void ParticleStateDeleter::operator()(ParticleState* state) const {
    delete state;
}

static gpu::GpuParticleEmitter gpuEmitter(const ParticleEmitter& e, uint32_t first) {
    gpu::GpuParticleEmitter g{};
    g.position = e.position;
    g.spawnRadius = e.spawnRadius;
    g.velocity = e.velocity;
    g.velocitySpread = e.velocitySpread;
    g.acceleration = e.acceleration;
    g.drag = e.drag;
    g.colorStart = e.colorStart;
    g.colorEnd = e.colorEnd;
    g.sizeStart = e.sizeStart;
    g.sizeEnd = e.sizeEnd;
    g.lifetime = e.lifetime;
    g.additiveness = std::clamp(e.additiveness, 0.0f, 1.0f);
    g.firstParticle = first;
    g.particleCount = e.particleCount;
    g.flags = (e.lit ? PARTICLE_EMITTER_LIT : 0u) | (e.mesh ? PARTICLE_EMITTER_MESH : 0u) |
              (e.vertexLit ? PARTICLE_EMITTER_VERTEX_LIT : 0u);
    g.bounce = e.bounce;
    g.seed = e.seed;
    g.lodBias = e.lodBias;
    g.turbulence = e.turbulence;
    g.wrap = e.wrap;
    g.normalScale = e.normalScale;
    return g;
}

ParticleStatePtr createParticles(Renderer& r, const GpuScene& scene) {
    if (!r.settings.particles || scene.emitters.empty()) return nullptr;
    Gpu& gpu = *r.gpu;
    ParticleStatePtr state(new ParticleState());
    ParticleState& s = *state;

    // Emitters, and their particles unborn with staggered ages: particle k of n is born
    // k/n of a lifetime after the start, so the prewarm reaches a steady stream.
    std::vector<gpu::GpuParticleEmitter> emitters;
    std::vector<gpu::GpuParticle> particles;
    for (uint32_t e = 0; e < scene.emitters.size(); ++e) {
        const ParticleEmitter& em = scene.emitters[e];
        if (em.particleCount == 0 || !(em.lifetime > 0.0f))
            throw InputError(format("particle emitter '%s': needs particles and a positive "
                                    "lifetime",
                                    em.name.c_str()));
        emitters.push_back(gpuEmitter(em, uint32_t(particles.size())));
        s.hasMeshes = s.hasMeshes || em.mesh;
        s.maxLifetime = std::max(s.maxLifetime, em.lifetime * 1.2f);
        for (uint32_t k = 0; k < em.particleCount; ++k) {
            gpu::GpuParticle p{};
            p.age = -em.lifetime * float(k) / float(em.particleCount);
            p.lifetime = em.lifetime;
            p.emitter = e;
            p.generation = PARTICLE_NOT_SPAWNED;
            p.atlasEntry = PARTICLE_NO_ATLAS;
            particles.push_back(p);
        }
    }
    s.particleCount = uint32_t(particles.size());
    s.particles = createBuffer(gpu, {"particles.state", particles.size() * sizeof(gpu::GpuParticle),
                                     VK_BUFFER_USAGE_TRANSFER_DST_BIT});
    s.emitters =
        createBuffer(gpu, {"particles.emitters", emitters.size() * sizeof(gpu::GpuParticleEmitter),
                           VK_BUFFER_USAGE_TRANSFER_DST_BIT});
    s.atlasCounts = createBuffer(gpu, {"particles.atlasCounts", sizeof(gpu::ParticleAtlasCounts),
                                       VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::Readback});
    s.frame =
        createBuffer(gpu, {"particles.frame", sizeof(gpu::ParticleFrame), 0, MemoryKind::Upload});
    if (!s.particles || !s.emitters || !s.atlasCounts || !s.frame)
        throw DeviceError("out of GPU memory for the particle buffers");
    uploadBuffer(gpu, s.particles, particles.data(), particles.size() * sizeof(gpu::GpuParticle));
    uploadBuffer(gpu, s.emitters, emitters.data(),
                 emitters.size() * sizeof(gpu::GpuParticleEmitter));

    TextureDesc atlas;
    atlas.name = "particles.lightmapAtlas";
    atlas.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    atlas.width = atlas.height = r.settings.particleAtlasSize;
    atlas.usage =
        VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    s.atlas = createTexture(gpu, atlas);
    if (!s.atlas) throw DeviceError("out of GPU memory for the particle lightmap atlas");
    s.atlasWrite = createWriteView(gpu, s.atlas);
    s.atlasRead = createReadView(gpu, s.atlas);
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) { // GENERAL for good: written and sampled
        imageBarrier(cmd, vkImage(gpu, s.atlas), VK_IMAGE_ASPECT_COLOR_BIT,
                     VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE,
                     0, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                     VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    });

    s.simulate = createComputePipeline(gpu, "particleSimulate", "particles_simulate.comp.spv");
    s.atlasLight =
        createComputePipeline(gpu, "particleAtlasLighting", "particles_atlas_light.comp.spv");
    GraphicsPipelineDesc sprites;
    sprites.name = "particleSprites";
    sprites.vertexShader = "particles_sprite.vert.spv";
    sprites.fragmentShader = "particles_sprite.frag.spv";
    sprites.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT};
    sprites.depthFormat = VK_FORMAT_D32_SFLOAT;
    sprites.depthWrite = false;
    sprites.depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL;
    sprites.cullMode = VK_CULL_MODE_NONE;
    sprites.attachmentBlends = wboitAttachmentBlends();
    s.sprites = createGraphicsPipeline(gpu, sprites);
    if (r.settings.particleHalfRes) {
        s.halfWidth = (r.internalWidth + 1) / 2;
        s.halfHeight = (r.internalHeight + 1) / 2;
        s.accumHalf =
            createWboitTarget(gpu, "particles.accumulationHalf", s.halfWidth, s.halfHeight);
        s.revealHalf = createWboitTarget(gpu, "particles.revealageAdditivenessHalf", s.halfWidth,
                                         s.halfHeight);
        s.accumHalfTarget = createRenderTargetView(gpu, s.accumHalf);
        s.revealHalfTarget = createRenderTargetView(gpu, s.revealHalf);
        s.accumHalfRead = createReadView(gpu, s.accumHalf);
        s.revealHalfRead = createReadView(gpu, s.revealHalf);
        GraphicsPipelineDesc half = sprites;
        half.name = "particleSpritesHalf";
        half.depthFormat = VK_FORMAT_UNDEFINED;
        half.depthTest = false;
        s.spritesHalf = createGraphicsPipeline(gpu, half);
    }
    GraphicsPipelineDesc meshes;
    meshes.name = "particleMeshes";
    meshes.vertexShader = "particles_mesh.vert.spv";
    meshes.fragmentShader = "particles_mesh.frag.spv";
    meshes.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT};
    meshes.depthFormat = VK_FORMAT_D32_SFLOAT;
    meshes.depthWrite = true; // opaque: later transparency is hidden behind them
    meshes.depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL;
    meshes.cullMode = VK_CULL_MODE_NONE; // closed boxes: depth keeps the front faces
    s.meshes = createGraphicsPipeline(gpu, meshes);
    GraphicsPipelineDesc view;
    view.name = "particleAtlasView";
    view.vertexShader = "oit_fullscreen.vert.spv";
    view.fragmentShader = "particles_atlas_view.frag.spv";
    view.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT};
    view.depthTest = false;
    view.depthWrite = false;
    view.cullMode = VK_CULL_MODE_NONE;
    s.atlasView = createGraphicsPipeline(gpu, view);
    return state;
}

void destroyParticles(Renderer& r, ParticleStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    ParticleState& s = *state;
    for (Pipeline* p : {&s.simulate, &s.atlasLight, &s.sprites, &s.atlasView, &s.meshes})
        destroy(gpu, *p);
    if (s.accumHalf) {
        destroy(gpu, s.spritesHalf);
        destroy(gpu, s.accumHalfTarget);
        destroy(gpu, s.revealHalfTarget);
        destroy(gpu, s.accumHalfRead);
        destroy(gpu, s.revealHalfRead);
        destroy(gpu, s.accumHalf);
        destroy(gpu, s.revealHalf);
    }
    destroy(gpu, s.atlasWrite);
    destroy(gpu, s.atlasRead);
    destroy(gpu, s.atlas);
    for (BufferHandle b : {s.particles, s.emitters, s.atlasCounts, s.frame}) destroy(gpu, b);
    state.reset();
}

void prepareParticleFrame(Renderer& r) {
    if (!r.particles) return;
    Gpu& gpu = *r.gpu;
    ParticleState& s = *r.particles;
    // Prewarm: the first frame runs a whole (longest) lifetime so emitters start full.
    s.stepsThisFrame =
        s.stepsTaken == 0 ? uint32_t(std::ceil(s.maxLifetime / kStepSeconds)) + 1u : 1u;
    gpu::ParticleFrame f{};
    f.particles = address(gpu, s.particles);
    f.emitters = address(gpu, s.emitters);
    f.atlasCounts = address(gpu, s.atlasCounts);
    f.particleCount = s.particleCount;
    f.steps = s.stepsThisFrame;
    f.dt = kStepSeconds;
    f.time = float(s.stepsTaken) * kStepSeconds;
    f.lighting = uint32_t(r.settings.particleLighting);
    f.atlasSize = r.settings.particleAtlasSize;
    f.atlasWriteSlot = slot(gpu, s.atlasWrite).value;
    f.atlasReadSlot = slot(gpu, s.atlasRead).value;
    f.halfRes = s.accumHalf ? 1u : 0u;
    f.depthReadSlot = slot(gpu, r.depthRead).value;
    std::memcpy(mapped(gpu, s.frame), &f, sizeof(f));
    s.stepsTaken += s.stepsThisFrame;
}

namespace {
struct ParticlePush {
    uint64_t frame;
    uint64_t particleFrame;
};
} // namespace

void recordParticlePasses(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    if (!r.particles) return;
    Gpu& gpu = *r.gpu;
    ParticleState& s = *r.particles;
    ParticlePush push{frame, address(gpu, s.frame)};
    pass(rec, "particleSimulate", [&, push](VkCommandBuffer cmd) {
        // Last frame's sprites and atlas lighting read the particles and counts.
        memoryBarrier(cmd,
                      VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
                          VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                          VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        vkCmdFillBuffer(cmd, vkBuffer(gpu, s.atlasCounts), 0, VK_WHOLE_SIZE, 0);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        bind(gpu, cmd, s.simulate);
        pushConstants(gpu, cmd, push);
        vkCmdDispatch(cmd, (s.particleCount + 63) / 64, 1, 1);
        memoryBarrier(
            cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
                VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    });
    if (s.hasMeshes && !r.visibility) // (--marking visibility leaves the colour in GENERAL)
        pass(rec, "particleMeshes", [&, push](VkCommandBuffer cmd) {
            // After the opaque scene's colour and depth, before the transparency tests them.
            memoryBarrier(cmd,
                          VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT |
                              VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                          VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                          VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT |
                              VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                              VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                          VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT |
                              VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
            beginSceneColorPass(r, cmd, false);
            VkViewport vp{0, 0, float(r.internalWidth), float(r.internalHeight), 0, 1};
            VkRect2D scissor{{0, 0}, {r.internalWidth, r.internalHeight}};
            vkCmdSetViewport(cmd, 0, 1, &vp);
            vkCmdSetScissor(cmd, 0, 1, &scissor);
            bind(gpu, cmd, s.meshes);
            pushConstants(gpu, cmd, push);
            vkCmdDraw(cmd, s.particleCount * PARTICLE_MESH_VERTICES, 1, 0, 0);
            vkCmdEndRendering(cmd);
        });
    if (r.settings.particleLighting != ParticleLighting::Atlas) return;
    pass(rec, "particleAtlasLighting", [&, push](VkCommandBuffer cmd) {
        VkImage atlas = vkImage(gpu, s.atlas);
        // Last frame's sprites sampled it (GENERAL throughout).
        imageBarrier(cmd, atlas, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                     VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                     VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_CLEAR_BIT,
                     VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);
        if (r.settings.visualize == Visualize::ParticleAtlas) { // unused texels black
            VkClearColorValue black{};
            VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
            vkCmdClearColorImage(cmd, atlas, VK_IMAGE_LAYOUT_GENERAL, &black, 1, &range);
            imageBarrier(cmd, atlas, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                         VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_CLEAR_BIT,
                         VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                         VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        }
        bind(gpu, cmd, s.atlasLight);
        pushConstants(gpu, cmd, push);
        vkCmdDispatch(cmd, s.particleCount, 1, 1);
        imageBarrier(cmd, atlas, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                     VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                     VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    });
}

bool particlesThisFrame(const Renderer& r) {
    return r.particles != nullptr && r.settings.oit == OitMode::Wboit;
}

void recordParticleSprites(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    if (!particlesThisFrame(r)) return;
    Gpu& gpu = *r.gpu;
    ParticleState& s = *r.particles;
    ParticlePush push{frame, address(gpu, s.frame)};
    if (!s.accumHalf) { // full resolution: into the surfaces' targets
        pass(rec, "particleSprites", [&, push](VkCommandBuffer cmd) {
            beginWboitTargets(r, cmd, false);
            bind(gpu, cmd, s.sprites);
            pushConstants(gpu, cmd, push);
            vkCmdDraw(cmd, s.particleCount * 6, 1, 0, 0);
            vkCmdEndRendering(cmd);
        });
        return;
    }
    pass(rec, "particleSpritesHalf", [&, push](VkCommandBuffer cmd) {
        // The opaque depth is read (2x2 per fragment) instead of attached.
        sceneDepthToSampled(r, cmd, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
        for (TextureHandle t : {s.accumHalf, s.revealHalf})
            imageBarrier(
                cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
        // Cleared as the surfaces' targets are: nothing accumulated, nothing hides or adds.
        ColorAttachment accum{vkView(gpu, s.accumHalfTarget), true};
        ColorAttachment reveal{vkView(gpu, s.revealHalfTarget), true};
        reveal.clearValue.float32[0] = 1.0f;
        reveal.clearValue.float32[1] = 1.0f;
        beginRendering(cmd, s.halfWidth, s.halfHeight, {accum, reveal});
        bind(gpu, cmd, s.spritesHalf);
        pushConstants(gpu, cmd, push);
        vkCmdDraw(cmd, s.particleCount * 6, 1, 0, 0);
        vkCmdEndRendering(cmd);
        for (TextureHandle t : {s.accumHalf, s.revealHalf})
            imageBarrier(
                cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT,
                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        sceneDepthToAttachment(r, cmd, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
    });
}

bool particleHalfResTargets(const Renderer& r, uint32_t& accumSlot, uint32_t& revealSlot) {
    if (!particlesThisFrame(r) || !r.particles->accumHalf) return false;
    accumSlot = slot(*r.gpu, r.particles->accumHalfRead).value;
    revealSlot = slot(*r.gpu, r.particles->revealHalfRead).value;
    return true;
}

void recordParticleAtlasView(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    if (!r.particles || r.settings.visualize != Visualize::ParticleAtlas) return;
    Gpu& gpu = *r.gpu;
    ParticleState& s = *r.particles;
    ParticlePush push{frame, address(gpu, s.frame)};
    pass(rec, "particleAtlasView", [&, push](VkCommandBuffer cmd) {
        memoryBarrier(
            cmd, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
            VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
            VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
        beginRendering(cmd, r.internalWidth, r.internalHeight, {{vkView(gpu, r.hdrTarget)}});
        bind(gpu, cmd, s.atlasView);
        pushConstants(gpu, cmd, push);
        vkCmdDraw(cmd, 3, 1, 0, 0);
        vkCmdEndRendering(cmd);
    });
}

ParticleStats readParticleStats(const Renderer& r) {
    ParticleStats st;
    if (!r.particles) return st;
    const ParticleState& s = *r.particles;
    gpu::ParticleAtlasCounts c{};
    std::memcpy(&c, mapped(*r.gpu, s.atlasCounts), sizeof(c));
    st.particles = s.particleCount;
    for (uint32_t l = 0; l < PARTICLE_ATLAS_LODS; ++l) {
        st.perLod[l] = c.perLod[l];
        st.atlasSprites += c.perLod[l];
    }
    st.atlasOverflowed = c.overflowed;
    st.atlasTexels = c.texels;
    st.atlasSize = r.settings.particleAtlasSize;
    st.simulatedSeconds = double(s.stepsTaken) * kStepSeconds;
    return st;
}

void particleStats(const Renderer& r, nlohmann::json& stats) {
    ParticleStats st = readParticleStats(r);
    const char* modes[] = {"atlas", "pixel", "vertex"};
    stats["particles"] = {{"particles", st.particles},
                          {"lighting", modes[uint32_t(r.settings.particleLighting)]},
                          {"resolution", r.particles && r.particles->accumHalf ? "half" : "full"},
                          {"atlas_sprites", st.atlasSprites},
                          {"atlas_overflowed", st.atlasOverflowed},
                          {"atlas_texels", st.atlasTexels},
                          {"atlas_size", st.atlasSize},
                          {"atlas_sprites_per_lod", st.perLod},
                          {"simulated_seconds", st.simulatedSeconds}};
}

} // namespace shadel
