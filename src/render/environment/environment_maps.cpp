#include "render/environment/environment_maps.h"

#include <algorithm>
#include <chrono>
#include <thread>

#include "core/error.h"
#include "core/log.h"
#include "core/worker_pool.h"
#include "render/environment/environment_cache.h"
#include "render/environment/environment_file.h"
#include "render/environment/hemisphere.h"
#include "render/environment/sky.h"
#include "scene/scene.h"

namespace shadel {

namespace {

constexpr uint32_t kSkyWidth = 1024;           // the sky's source and background
constexpr uint32_t kMaxBackgroundWidth = 2048; // a file's background, at most

struct Hasher {
    BakeKey key{0x243F6A8885A308D3ull, 0x13198A2E03707344ull};
    void add(const void* data, size_t size) {
        key.lo = hashBytes(data, size, key.lo);
        key.hi = hashBytes(data, size, key.hi ^ 0x5851F42D4C957F2Dull);
    }
    template <typename T>
    void add(const T& value) {
        add(&value, sizeof value);
    }
};

uint32_t threadCount(uint32_t threads) {
    if (threads) return threads;
    return std::clamp(std::thread::hardware_concurrency(), 1u, 16u);
}

std::string describe(const EnvironmentRequest& r) {
    switch (r.kind) {
    case EnvironmentKind::File:
        return r.path;
    case EnvironmentKind::Sky:
        return "builtin:sky";
    case EnvironmentKind::Hemisphere:
        return "the scene's hemisphere";
    default:
        return "none";
    }
}

BakeKey sourceKey(const EnvironmentRequest& r, const std::vector<uint8_t>& fileBytes,
                  const PrefilterSettings& s) {
    Hasher h;
    h.add(kEnvironmentFormatVersion);
    h.add(uint32_t(r.kind));
    h.add(s.specularWidth), h.add(s.specularLevels), h.add(s.specularSamples), h.add(s.sheenWidth);
    h.add(s.sheenLevels);
    h.add(s.irradianceWidth);
    if (r.kind == EnvironmentKind::File) h.add(fileBytes.data(), fileBytes.size());
    if (r.kind == EnvironmentKind::Sky) h.add(glm::normalize(r.sunDirection)), h.add(r.sunColor);
    if (r.kind == EnvironmentKind::Hemisphere) h.add(r.skyColor), h.add(r.ambientColor);
    return h.key;
}

EquirectImage decodeSource(const EnvironmentRequest& r, const std::vector<uint8_t>& fileBytes,
                           WorkerPool& pool) {
    switch (r.kind) {
    case EnvironmentKind::File:
        return decodeEnvironmentFile(r.path, fileBytes);
    case EnvironmentKind::Sky: {
        SkyParameters sky;
        sky.sunDirection = r.sunDirection;
        sky.sunColor = r.sunColor;
        return renderSky(sky, kSkyWidth, kSkyWidth / 2, pool);
    }
    case EnvironmentKind::Hemisphere:
        return hemisphereRadiance(r.skyColor, r.ambientColor, 64, 32);
    default:
        return makeEquirect(8, 4);
    }
}

EquirectImage backgroundOf(const EnvironmentRequest& r, const EquirectImage& source) {
    if (r.kind == EnvironmentKind::Hemisphere) return makeEquirect(8, 4, r.skyColor);
    if (source.width > kMaxBackgroundWidth)
        return resampleEquirect(source, kMaxBackgroundWidth, kMaxBackgroundWidth / 2);
    return source;
}

// Cached images: background, irradiance, the specular levels, then the sheen levels.
bool chainFits(const std::vector<EquirectImage>& images, size_t first, uint32_t width,
               uint32_t levels) {
    for (uint32_t l = 0; l < levels; ++l)
        if (images[first + l].width != std::max(width >> l, 2u) ||
            images[first + l].height != std::max((width / 2) >> l, 1u))
            return false;
    return true;
}

bool cachedMapsFit(const std::vector<EquirectImage>& images, const PrefilterSettings& s) {
    if (images.size() != 2 + size_t(s.specularLevels) + sheenLevelCount(s)) return false;
    if (images[1].width != s.irradianceWidth || images[1].height != s.irradianceWidth / 2)
        return false;
    return chainFits(images, 2, s.specularWidth, s.specularLevels) &&
           chainFits(images, 2 + s.specularLevels, s.sheenWidth, sheenLevelCount(s));
}

BrdfTable loadBrdfTable(const std::string& cacheDir, uint32_t size, WorkerPool& pool) {
    Hasher h;
    h.add(kEnvironmentFormatVersion), h.add(size);
    h.add("brdf", 4);
    std::string path = cacheDir.empty() ? "" : environmentCachePath(cacheDir, h.key);
    std::vector<EquirectImage> images;
    std::string why;
    if (!path.empty() && readEnvironmentCache(path, h.key, images, &why) && images.size() == 1 &&
        images[0].width == size && images[0].height == size)
        return {size, std::move(images[0].texels)};
    if (!path.empty() && why != "missing")
        SHADEL_WARN("environment: %s: %s; rebuilding it", path.c_str(), why.c_str());
    BrdfTable table = integrateBrdf(size, pool);
    if (!path.empty()) {
        EquirectImage image{size, size, table.texels};
        if (!writeEnvironmentCache(path, h.key, {image}, &why))
            SHADEL_WARN("environment: cache not written: %s", why.c_str());
    }
    return table;
}

} // namespace

EnvironmentRequest environmentRequest(const std::string& setting, bool settingGiven,
                                      const Scene& scene, glm::vec3 sunDirection,
                                      glm::vec3 sunColor) {
    return environmentRequest(setting, settingGiven, scene.environment, scene.skyColor,
                              scene.ambientColor, sunDirection, sunColor);
}

EnvironmentRequest environmentRequest(const std::string& setting, bool settingGiven,
                                      Scene::Environment sceneEnvironment, glm::vec3 skyColor,
                                      glm::vec3 ambientColor, glm::vec3 sunDirection,
                                      glm::vec3 sunColor) {
    EnvironmentRequest r;
    r.sunDirection = sunDirection, r.sunColor = sunColor;
    r.skyColor = skyColor, r.ambientColor = ambientColor;
    if (!settingGiven && sceneEnvironment == Scene::Environment::Hemisphere) {
        r.kind = EnvironmentKind::Hemisphere;
    } else if (setting == "none") {
        r.kind = EnvironmentKind::None;
    } else if (setting == "builtin:sky") {
        r.kind = EnvironmentKind::Sky;
    } else if (setting.rfind("builtin:", 0) == 0) {
        throw InputError(
            format("--environment %s: unknown; the built-in one is builtin:sky", setting.c_str()));
    } else {
        r.kind = EnvironmentKind::File;
        r.path = setting;
    }
    return r;
}

EquirectImage environmentSource(const EnvironmentRequest& request, uint32_t threads) {
    WorkerPool pool(threadCount(threads));
    std::vector<uint8_t> bytes;
    if (request.kind == EnvironmentKind::File) bytes = readEnvironmentFile(request.path);
    return decodeSource(request, bytes, pool);
}

EnvironmentMaps loadEnvironmentMaps(const EnvironmentRequest& request, const std::string& cacheDir,
                                    const PrefilterSettings& settings, uint32_t threads) {
    EnvironmentMaps maps;
    maps.kind = request.kind;
    auto start = std::chrono::steady_clock::now();
    WorkerPool pool(threadCount(threads));
    if (request.kind == EnvironmentKind::None) { // black lighting; the BRDF table still serves
        maps.brdf = loadBrdfTable(cacheDir, settings.brdfSize, pool);
        return maps;
    }
    if (request.kind == EnvironmentKind::Sky) {
        maps.sunDirection = glm::normalize(request.sunDirection);
        maps.sunDiscRadiance = sunDiscRadiance(request.sunColor);
    }
    std::vector<uint8_t> bytes;
    if (request.kind == EnvironmentKind::File) bytes = readEnvironmentFile(request.path);
    BakeKey key = sourceKey(request, bytes, settings);
    std::string path = cacheDir.empty() ? "" : environmentCachePath(cacheDir, key);
    std::string name = describe(request), why;
    std::vector<EquirectImage> images;
    if (!path.empty() && readEnvironmentCache(path, key, images, &why) &&
        cachedMapsFit(images, settings)) {
        maps.fromCache = true;
    } else {
        if (!path.empty() && why != "missing")
            SHADEL_WARN("environment: %s: %s; rebuilding it", path.c_str(),
                        why.empty() ? "other sizes" : why.c_str());
        EquirectImage source = decodeSource(request, bytes, pool);
        int reported = -1;
        auto progress = [&](float done) {
            int quarter = int(done * 4.0f);
            if (quarter > reported) {
                reported = quarter;
                SHADEL_INFO("environment: prefiltering %s ... %d%%", name.c_str(), quarter * 25);
            }
        };
        // The sheen chain is a quarter of the specular one's size: a sixteenth of the work.
        std::vector<EquirectImage> specular =
            prefilterSpecular(source, settings, pool, [&](float done) { progress(done * 0.94f); });
        std::vector<EquirectImage> sheen = prefilterSheen(
            source, settings, pool, [&](float done) { progress(0.94f + done * 0.06f); });
        images = {backgroundOf(request, source),
                  prefilterIrradiance(specular[0], settings.irradianceWidth, pool)};
        for (EquirectImage& level : specular) images.push_back(std::move(level));
        for (EquirectImage& level : sheen) images.push_back(std::move(level));
        if (!path.empty() && !writeEnvironmentCache(path, key, images, &why))
            SHADEL_WARN("environment: cache not written: %s", why.c_str());
    }
    maps.background = std::move(images[0]);
    maps.irradiance = std::move(images[1]);
    auto sheenBegin = images.begin() + 2 + settings.specularLevels;
    maps.specular.assign(std::make_move_iterator(images.begin() + 2),
                         std::make_move_iterator(sheenBegin));
    maps.sheen.assign(std::make_move_iterator(sheenBegin), std::make_move_iterator(images.end()));
    maps.brdf = loadBrdfTable(cacheDir, settings.brdfSize, pool);
    maps.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    SHADEL_INFO("environment: %s %s in %.2f s", name.c_str(),
                maps.fromCache ? "loaded from the cache" : "prefiltered", maps.seconds);
    return maps;
}

} // namespace shadel
