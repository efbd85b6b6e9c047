#include "render/environment/environment_state.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/packing.hpp>

#include "core/error.h"
#include "render/environment/sky.h"
#include "render/gpu_scene.h"
#include "render/renderer.h"
#include "rhi/resources.h"

namespace shadel {

static_assert(sizeof(gpu::GpuEnvironment) == 96, "GpuEnvironment: scalar layout, 96 bytes");

namespace {

struct Level {
    uint32_t width, height;
    const std::vector<glm::vec3>* texels;
};

bool linearFilterable(Gpu& gpu, VkFormat format) {
    VkFormatProperties p;
    vkGetPhysicalDeviceFormatProperties(gpu.device.physical, format, &p);
    return (p.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) != 0;
}

// RGBA texels of every level, packed back to back as `format` (RGBA32F or RGBA16F; half floats
// saturate at 65504).
std::vector<uint8_t> packLevels(const std::vector<Level>& levels, VkFormat format,
                                std::vector<VkDeviceSize>& offsets) {
    bool half = format == VK_FORMAT_R16G16B16A16_SFLOAT;
    size_t texelBytes = half ? 8 : 16;
    std::vector<uint8_t> bytes;
    for (const Level& l : levels) {
        offsets.push_back(bytes.size());
        size_t start = bytes.size();
        bytes.resize(start + l.texels->size() * texelBytes);
        uint8_t* out = bytes.data() + start;
        for (size_t i = 0; i < l.texels->size(); ++i) {
            glm::vec4 c((*l.texels)[i], 1.0f);
            if (half) {
                glm::uvec2 h(
                    glm::packHalf2x16(glm::vec2(std::min(c.r, 65504.0f), std::min(c.g, 65504.0f))),
                    glm::packHalf2x16(glm::vec2(std::min(c.b, 65504.0f), 1.0f)));
                std::memcpy(out + i * 8, &h, 8);
            } else {
                std::memcpy(out + i * 16, &c, 16);
            }
        }
    }
    return bytes;
}

TextureHandle uploadLevels(Gpu& gpu, const std::string& name, VkFormat format,
                           const std::vector<Level>& levels) {
    TextureDesc d;
    d.name = name;
    d.format = format;
    d.width = levels[0].width, d.height = levels[0].height;
    d.mipLevels = uint32_t(levels.size());
    d.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    TextureHandle texture = createTexture(gpu, d);
    if (!texture) throw DeviceError("out of device memory for " + name);
    std::vector<VkDeviceSize> offsets;
    std::vector<uint8_t> bytes = packLevels(levels, format, offsets);
    BufferHandle staging =
        createBuffer(gpu, {"staging." + name, bytes.size(), 0, MemoryKind::Upload});
    if (!staging) throw DeviceError("out of host-visible memory for " + name);
    std::memcpy(mapped(gpu, staging), bytes.data(), bytes.size());
    VkImage image = vkImage(gpu, texture);
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                     VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        std::vector<VkBufferImageCopy> copies;
        for (uint32_t l = 0; l < levels.size(); ++l) {
            VkBufferImageCopy c{};
            c.bufferOffset = offsets[l];
            c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, 1};
            c.imageExtent = {levels[l].width, levels[l].height, 1};
            copies.push_back(c);
        }
        vkCmdCopyBufferToImage(cmd, vkBuffer(gpu, staging), image,
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, uint32_t(copies.size()),
                               copies.data());
        imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                     VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    });
    destroy(gpu, staging);
    return texture;
}

TextureHandle uploadImage(Gpu& gpu, const std::string& name, VkFormat format,
                          const EquirectImage& image) {
    return uploadLevels(gpu, name, format, {{image.width, image.height, &image.texels}});
}

} // namespace

void createEnvironment(Gpu& gpu, EnvironmentState& state, const EnvironmentMaps& maps,
                       float intensity, float rotationDegrees) {
    destroyEnvironment(gpu, state);
    state.kind = maps.kind;
    state.fromCache = maps.fromCache;
    state.seconds = maps.seconds;
    gpu::GpuEnvironment& c = state.constants;
    c = {};
    if (!maps.brdf.texels.empty()) {
        EquirectImage table{maps.brdf.size, maps.brdf.size, maps.brdf.texels};
        state.brdf = uploadImage(gpu, "environment.brdf", VK_FORMAT_R16G16B16A16_SFLOAT, table);
        state.brdfView = createReadView(gpu, state.brdf);
        c.brdfSlot = slot(gpu, state.brdfView).value;
        c.brdfSize = float(maps.brdf.size);
    }
    if (maps.kind == EnvironmentKind::None || maps.specular.empty()) {
        c.flags = ENVIRONMENT_FLAG_NONE;
        setEnvironmentView(state, intensity, rotationDegrees);
        return;
    }
    // 32-bit floats keep a sun-bright file's texels; half floats where filtering needs them.
    VkFormat light = linearFilterable(gpu, VK_FORMAT_R32G32B32A32_SFLOAT)
                         ? VK_FORMAT_R32G32B32A32_SFLOAT
                         : VK_FORMAT_R16G16B16A16_SFLOAT;
    std::vector<Level> levels;
    for (const EquirectImage& l : maps.specular) levels.push_back({l.width, l.height, &l.texels});
    state.specular = uploadLevels(gpu, "environment.specular", light, levels);
    if (!maps.sheen.empty()) {
        std::vector<Level> sheenLevels;
        for (const EquirectImage& l : maps.sheen)
            sheenLevels.push_back({l.width, l.height, &l.texels});
        state.sheen = uploadLevels(gpu, "environment.sheen", light, sheenLevels);
        state.sheenView = createReadView(gpu, state.sheen);
        c.sheenSlot = slot(gpu, state.sheenView).value;
        c.sheenLevels = uint32_t(maps.sheen.size());
        c.sheenHeight = float(maps.sheen[0].height);
    }
    state.irradiance = uploadImage(gpu, "environment.irradiance", light, maps.irradiance);
    state.background =
        uploadImage(gpu, "environment.background", VK_FORMAT_R16G16B16A16_SFLOAT, maps.background);
    state.specularView = createReadView(gpu, state.specular);
    state.irradianceView = createReadView(gpu, state.irradiance);
    state.backgroundView = createReadView(gpu, state.background);
    c.specularSlot = slot(gpu, state.specularView).value;
    c.irradianceSlot = slot(gpu, state.irradianceView).value;
    c.backgroundSlot = slot(gpu, state.backgroundView).value;
    c.specularLevels = uint32_t(maps.specular.size());
    c.specularHeight = float(maps.specular[0].height);
    c.irradianceHeight = float(maps.irradiance.height);
    c.backgroundHeight = float(maps.background.height);
    c.sunDirection = maps.sunDirection;
    c.sunRadiance = maps.sunDiscRadiance;
    c.sunCosRadius = float(std::cos(kSunAngularRadius));
    if (maps.sunDiscRadiance != glm::vec3(0.0f)) c.flags |= ENVIRONMENT_FLAG_SUN_DISC;
    setEnvironmentView(state, intensity, rotationDegrees);
}

void createEnvironment(Gpu& gpu, EnvironmentState& state, const RenderSettings& settings,
                       const GpuScene& scene, const std::string& cacheDir) {
    EnvironmentRequest request =
        environmentRequest(settings.environment, settings.environmentGiven, scene.environment,
                           scene.skyColor, scene.ambientColor, scene.sunDirection, scene.sunColor);
    EnvironmentMaps maps = loadEnvironmentMaps(request, cacheDir);
    createEnvironment(gpu, state, maps, settings.environmentIntensity,
                      settings.environmentRotationDegrees);
}

void setEnvironmentView(EnvironmentState& state, float intensity, float rotationDegrees) {
    double a = double(rotationDegrees) * 3.14159265358979323846 / 180.0;
    state.constants.intensity = intensity;
    state.constants.rotationCos = float(std::cos(a));
    state.constants.rotationSin = float(std::sin(a));
}

void destroyEnvironment(Gpu& gpu, EnvironmentState& state) {
    for (TextureReadView* v : {&state.specularView, &state.irradianceView, &state.backgroundView,
                               &state.brdfView, &state.sheenView})
        if (v->valid()) destroy(gpu, *v), *v = {};
    for (TextureHandle* t :
         {&state.specular, &state.irradiance, &state.background, &state.brdf, &state.sheen})
        if (t->valid()) destroy(gpu, *t), *t = {};
    state.constants = {};
    state.constants.flags = ENVIRONMENT_FLAG_NONE;
}

} // namespace shadel
