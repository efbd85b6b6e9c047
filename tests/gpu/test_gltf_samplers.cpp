// glTF samplers and face culling as authored, against CPU oracles. Unlit textured quads under an
// orthographic camera map texels to known pixels: each pixel's expected colour is the texture's
// wrap (repeat, mirrored repeat, clamp to edge) and filter (nearest, bilinear, level 0 only or
// mipmapped) worked out on the CPU, then the display encoding (ACES fit, sRGB, 8 bits). Culling:
// single-sided quads seen from behind show the background, double-sided ones their flipped-
// normal colour, and a mirrored (negative-scale) instance is not turned inside out. Normal maps:
// a quad whose normal texture tilts its normal lights as a quad whose geometry is tilted as
// much. Exposure: an unlit colour times the exposure, then the display encoding, with the tonemap
// fused into shading or as its own pass. Every case in both paths.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <stb/stb_image_write.h> // defined once, in scene/gltf_import.cpp

#include "gpu_test_env.h"

using namespace shadel;
using namespace shadel::test;

namespace {

constexpr int kRepeat = 10497, kMirror = 33648, kClamp = 33071;
constexpr int kWrapModes[3] = {kRepeat, kMirror, kClamp};
constexpr int kNearest = 9728, kLinear = 9729;
constexpr int kMinFilters[6] = {9728, 9729, 9984, 9985, 9986, 9987};

struct Rgb {
    double r, g, b;
};

double srgbToLinear(double c8) {
    double c = c8 / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// The display encoding of an unlit colour (shaders/common/tone_curve.glsl displayColor).
double displayLevel(double linear) {
    double x = std::max(linear, 0.0);
    double y = std::clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
    double s = y <= 0.0031308 ? y * 12.92 : 1.055 * std::pow(y, 1.0 / 2.4) - 0.055;
    return std::clamp(s, 0.0, 1.0) * 255.0;
}

// The scene colour a displayed 8-bit level came from (the display encoding undone).
double undisplay(double level) {
    double y = std::clamp(srgbToLinear(level), 0.0, 0.999);
    double a = 2.43 * y - 2.51, b = 0.59 * y - 0.03, c = 0.14 * y;
    return std::max((-b - std::sqrt(std::max(b * b - 4.0 * a * c, 0.0))) / (2.0 * a), 0.0);
}

// A channel's error: in display levels, or in 8-bit steps of linear light where that is less.
// Filtering sRGB texels happens in linear light, where lavapipe keeps 8 bits: in the dark the
// display encoding magnifies one linear step to several display levels.
double channelError(double level, double expectedLinear) {
    return std::min(std::abs(level - displayLevel(expectedLinear)),
                    255.0 * std::abs(undisplay(level) - expectedLinear));
}

// An sRGB RGBA8 texture and its texels in linear light.
struct TestTexture {
    int size = 0;
    std::vector<uint8_t> rgba;
    Rgb linear(int x, int y) const {
        const uint8_t* p = &rgba[size_t(y * size + x) * 4];
        return {srgbToLinear(p[0]), srgbToLinear(p[1]), srgbToLinear(p[2])};
    }
};

// 4 x 4, every texel a different colour.
TestTexture paletteTexture() {
    TestTexture t{4, std::vector<uint8_t>(4 * 4 * 4)};
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            uint8_t* p = &t.rgba[size_t(y * 4 + x) * 4];
            p[0] = uint8_t(30 + 65 * x), p[1] = uint8_t(30 + 65 * y);
            p[2] = uint8_t(((x + 2 * y) % 3) * 100 + 20), p[3] = 255;
        }
    return t;
}

// 8 x 8, a one-texel checker of two colours (A where x + y is even).
TestTexture checkerTexture() {
    TestTexture t{8, std::vector<uint8_t>(8 * 8 * 4)};
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            uint8_t* p = &t.rgba[size_t(y * 8 + x) * 4];
            bool a = (x + y) % 2 == 0;
            p[0] = a ? 230 : 30, p[1] = a ? 60 : 90, p[2] = a ? 40 : 210, p[3] = 255;
        }
    return t;
}

// A texel index wrapped as the sampler's address mode does.
int wrapIndex(int i, int n, int mode) {
    if (mode == kClamp) return std::clamp(i, 0, n - 1);
    if (mode == kRepeat) return ((i % n) + n) % n;
    int m = ((i % (2 * n)) + 2 * n) % (2 * n);
    return m < n ? m : 2 * n - 1 - m;
}

// Level 0 at texel coordinates (tx, ty) (texel units, 0 = the texture's left/top edge).
Rgb sampleLevel0(const TestTexture& t, double tx, double ty, int wrapS, int wrapT, bool linear) {
    if (!linear)
        return t.linear(wrapIndex(int(std::floor(tx)), t.size, wrapS),
                        wrapIndex(int(std::floor(ty)), t.size, wrapT));
    double fx = tx - 0.5, fy = ty - 0.5;
    int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
    double ax = fx - x0, ay = fy - y0;
    Rgb out{0, 0, 0};
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            double w = (i ? ax : 1 - ax) * (j ? ay : 1 - ay);
            Rgb c = t.linear(wrapIndex(x0 + i, t.size, wrapS), wrapIndex(y0 + j, t.size, wrapT));
            out.r += w * c.r, out.g += w * c.g, out.b += w * c.b;
        }
    return out;
}

// One quad of a test scene: 2 x 2 world units facing +Z, centred at `centre`, its texture
// coordinates running from uv0 (top-left corner) to uv1 (bottom-right).
struct Quad {
    glm::vec2 centre{0.0f};
    int material = 0;
    glm::vec2 uv0{0.0f}, uv1{1.0f};
    nlohmann::json rotation, scale; // the node's, when not null
};

// Writes the quads with their materials, textures and an orthographic camera ("ortho", at
// z = 5 looking down -Z, seeing xmag x ymag half-extents); returns the .gltf path.
std::string writeQuads(const std::string& name, const std::vector<Quad>& quads,
                       const nlohmann::json& materials, const TestTexture* texture,
                       const nlohmann::json& samplers, float xmag, float ymag,
                       const nlohmann::json& lights = nullptr,
                       const nlohmann::json& lightRotation = nullptr) {
    nlohmann::json doc;
    doc["asset"] = {{"version", "2.0"}};
    doc["extensionsUsed"] = {"KHR_materials_unlit", "KHR_lights_punctual"};
    std::vector<float> floats;
    std::vector<uint16_t> indices = {0, 1, 2, 0, 2, 3};
    doc["scene"] = 0;
    doc["scenes"] = {{{"nodes", nlohmann::json::array()}}};
    for (const Quad& q : quads) {
        size_t base = floats.size() * 4;
        const float pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
        floats.insert(floats.end(), pos, pos + 12);
        for (int v = 0; v < 4; ++v) floats.insert(floats.end(), {0.0f, 0.0f, 1.0f});
        const float uv[8] = {q.uv0.x, q.uv1.y, q.uv1.x, q.uv1.y,
                             q.uv1.x, q.uv0.y, q.uv0.x, q.uv0.y};
        floats.insert(floats.end(), uv, uv + 8);
        int view = int(doc["bufferViews"].size());
        doc["bufferViews"].push_back(gltfBufferView(base, 48));
        doc["bufferViews"].push_back(gltfBufferView(base + 48, 48));
        doc["bufferViews"].push_back(gltfBufferView(base + 96, 32));
        int accessor = int(doc["accessors"].size());
        nlohmann::json position = gltfAccessor(view, 5126, 4, "VEC3");
        position["min"] = {-1, -1, 0};
        position["max"] = {1, 1, 0};
        doc["accessors"].push_back(position);
        doc["accessors"].push_back(gltfAccessor(view + 1, 5126, 4, "VEC3"));
        doc["accessors"].push_back(gltfAccessor(view + 2, 5126, 4, "VEC2"));
        nlohmann::json primitive;
        primitive["attributes"] = {
            {"POSITION", accessor}, {"NORMAL", accessor + 1}, {"TEXCOORD_0", accessor + 2}};
        primitive["indices"] = 3 * quads.size();
        primitive["material"] = q.material;
        nlohmann::json mesh;
        mesh["primitives"] = nlohmann::json::array({primitive});
        doc["meshes"].push_back(mesh);
        nlohmann::json node = {{"mesh", doc["meshes"].size() - 1},
                               {"translation", {q.centre.x, q.centre.y, 0.0f}}};
        if (!q.rotation.is_null()) node["rotation"] = q.rotation;
        if (!q.scale.is_null()) node["scale"] = q.scale;
        doc["scenes"][0]["nodes"].push_back(doc["nodes"].size());
        doc["nodes"].push_back(node);
    }
    doc["bufferViews"].push_back(gltfBufferView(floats.size() * 4, 12));
    doc["accessors"].push_back(gltfAccessor(int(doc["bufferViews"].size()) - 1, 5123, 6, "SCALAR"));
    doc["materials"] = materials;
    if (texture) {
        std::string png = tempPath(name + ".png");
        EXPECT_NE(stbi_write_png(png.c_str(), texture->size, texture->size, 4, texture->rgba.data(),
                                 texture->size * 4),
                  0);
        doc["images"] = {{{"uri", std::filesystem::path(png).filename().string()}}};
        doc["samplers"] = samplers;
        for (size_t s = 0; s < samplers.size(); ++s)
            doc["textures"].push_back({{"source", 0}, {"sampler", s}});
    }
    doc["cameras"] = {
        {{"type", "orthographic"},
         {"orthographic", {{"xmag", xmag}, {"ymag", ymag}, {"znear", 0.1}, {"zfar", 20.0}}}}};
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size());
    doc["nodes"].push_back({{"name", "ortho"}, {"camera", 0}, {"translation", {0.0, 0.0, 5.0}}});
    if (!lights.is_null()) {
        doc["extensions"] = {{"KHR_lights_punctual", {{"lights", lights}}}};
        doc["scenes"][0]["nodes"].push_back(doc["nodes"].size());
        // Pointing down -Z, the way the camera looks: light arrives from the viewer (unless the
        // node is rotated).
        nlohmann::json node = {{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}};
        if (!lightRotation.is_null()) node["rotation"] = lightRotation;
        doc["nodes"].push_back(node);
    }
    return writeGltf(name, doc, floats, indices);
}

nlohmann::json unlitTextured(int texture) {
    return {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", texture}}}}},
            {"extensions", {{"KHR_materials_unlit", nlohmann::json::object()}}}};
}

RenderRun renderOrtho(const std::string& file, RenderMode mode, uint32_t w, uint32_t h) {
    RenderOptions o = renderOptions(file, mode, w, h);
    o.progress = false;
    o.camera = "ortho";
    return renderChecked(o);
}

// Compares an image region with expected linear colours: the largest channelError over the
// pixels `use` accepts.
template <typename Expected, typename Use>
double worstError(const RenderRun& run, uint32_t width, int x0, int y0, int w, int h,
                  Expected&& expected, Use&& use) {
    const std::vector<uint8_t>& img = run.frames.back().rgba;
    double worst = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!use(x, y)) continue;
            Rgb e = expected(x, y);
            const uint8_t* p = &img[(size_t(y0 + y) * width + size_t(x0 + x)) * 4];
            double d = std::max(
                {channelError(p[0], e.r), channelError(p[1], e.g), channelError(p[2], e.b)});
            worst = std::max(worst, d);
        }
    return worst;
}

const char* modeLabel(RenderMode m) {
    return m == RenderMode::Forward ? "forward" : "decoupled";
}

// The nine wrap combinations side by side (3 x 3 quads of 96 x 96 pixels), each quad's texture
// coordinates over [-1, 2]: the 4 x 4 palette repeats, mirrors or clamps three times across,
// 8 pixels per texel. Pixel centres fall at 1/16 texel from texel edges, never on one.
// Returns the worst error per quad.
std::vector<double> wrapGridErrors(RenderMode mode, int magFilter) {
    TestTexture tex = paletteTexture();
    std::vector<Quad> quads;
    nlohmann::json materials = nlohmann::json::array(), samplers = nlohmann::json::array();
    for (int k = 0; k < 9; ++k) {
        Quad q;
        q.centre = {-2.0f + 2.0f * float(k % 3), 2.0f - 2.0f * float(k / 3)};
        q.material = k;
        q.uv0 = {-1.0f, -1.0f};
        q.uv1 = {2.0f, 2.0f};
        quads.push_back(q);
        materials.push_back(unlitTextured(k));
        samplers.push_back({{"wrapS", kWrapModes[k / 3]},
                            {"wrapT", kWrapModes[k % 3]},
                            {"magFilter", magFilter},
                            {"minFilter", kLinear}});
    }
    std::string name =
        std::string("samplers_wrap_") + (magFilter == kNearest ? "nearest" : "linear");
    std::string file = writeQuads(name, quads, materials, &tex, samplers, 3.0f, 3.0f);
    RenderRun run = renderOrtho(file, mode, 288, 288);
    std::vector<double> errors;
    bool decoupled = mode == RenderMode::Decoupled;
    for (int k = 0; k < 9; ++k) {
        int wrapS = kWrapModes[k / 3], wrapT = kWrapModes[k % 3];
        auto texel = [](int p) { return -4.0 + (p + 0.5) / 8.0; }; // u * 4 at pixel p
        auto expected = [&](int x, int y) {
            return sampleLevel0(tex, texel(x), texel(y), wrapS, wrapT, magFilter == kLinear);
        };
        // Decoupled pixels are interpolated between shadels, which magnified textures shade
        // coarser than pixels (render/shadel/texture_rate.h): they are compared where the texture
        // is smooth, away from the quad's border and, by 2 pixels, from where the filtered
        // texture bends: nearest filtering's texel edges, bilinear filtering's texel centres.
        auto use = [&](int x, int y) {
            if (!decoupled) return true;
            if (x < 2 || y < 2 || x > 93 || y > 93) return false;
            int bend = magFilter == kLinear ? 4 : 0; // where the texture bends, mod 8
            auto away = [&](int p) {
                int d = ((p - bend) % 8 + 8) % 8; // pixel p's centre is d + 0.5 past a bend
                return d >= 2 && d <= 5;
            };
            return away(x) && away(y);
        };
        errors.push_back(worstError(run, 288, 96 * (k % 3), 96 * (k / 3), 96, 96, expected, use));
    }
    return errors;
}

} // namespace

TEST(GltfSamplers, WrapModesMatchTheCpuOracle) {
    const char* wrapName[3] = {"repeat", "mirror", "clamp"};
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled})
        for (int mag : {kNearest, kLinear}) {
            std::vector<double> errors = wrapGridErrors(mode, mag);
            for (int k = 0; k < 9; ++k) {
                std::printf("%s, mag %s, wrapS %s wrapT %s: worst error %.1f levels\n",
                            modeLabel(mode), mag == kNearest ? "nearest" : "linear",
                            wrapName[k / 3], wrapName[k % 3], errors[size_t(k)]);
                // Measured worst (nearest, forward and decoupled: 0.5; bilinear: forward 5.0,
                // lavapipe filtering with 8-bit weights and 8-bit linear texels, decoupled 3.4).
                double floor = mag == kNearest ? 1.0 : mode == RenderMode::Forward ? 5.5 : 3.8;
                EXPECT_LE(errors[size_t(k)], floor)
                    << modeLabel(mode) << " mag " << mag << " wrapS " << wrapName[k / 3]
                    << " wrapT " << wrapName[k % 3] << ": measured " << errors[size_t(k)];
            }
        }
}

// The six minification filters side by side (3 x 2 quads of 32 x 32 pixels), each minifying an
// 8 x 8 one-texel checker exactly 2x (level of detail 1), offset a quarter texel: the filters
// without mipmaps read level 0 (nearest: one checker colour everywhere; linear: a fixed 5:3 mix
// of the two), the mipmapped ones level 1, the two colours' mean.
TEST(GltfSamplers, MinificationFiltersReadTheLevelsTheyName) {
    TestTexture tex = checkerTexture();
    std::vector<Quad> quads;
    nlohmann::json materials = nlohmann::json::array(), samplers = nlohmann::json::array();
    for (int k = 0; k < 6; ++k) {
        Quad q;
        q.centre = {-2.0f + 2.0f * float(k % 3), 1.0f - 2.0f * float(k / 3)};
        q.material = k;
        q.uv0 = {0.25f / 8.0f, 0.25f / 8.0f};
        q.uv1 = q.uv0 + glm::vec2(8.0f);
        quads.push_back(q);
        materials.push_back(unlitTextured(k));
        samplers.push_back({{"magFilter", kLinear}, {"minFilter", kMinFilters[k]}});
    }
    std::string file = writeQuads("samplers_min", quads, materials, &tex, samplers, 3.0f, 2.0f);
    Rgb a = tex.linear(0, 0), b = tex.linear(1, 0);
    Rgb mean{(a.r + b.r) / 2, (a.g + b.g) / 2, (a.b + b.b) / 2};
    const char* names[6] = {"nearest",
                            "linear",
                            "nearest_mipmap_nearest",
                            "linear_mipmap_nearest",
                            "nearest_mipmap_linear",
                            "linear_mipmap_linear"};
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        RenderRun run = renderOrtho(file, mode, 96, 64);
        bool decoupled = mode == RenderMode::Decoupled;
        for (int k = 0; k < 6; ++k) {
            bool level0 = k < 2;
            auto expected = [&](int x, int y) {
                if (!level0) return mean;
                return sampleLevel0(tex, 2.0 * x + 1.25, 2.0 * y + 1.25, kRepeat, kRepeat, k == 1);
            };
            auto inside = [&](int x, int y) {
                return !decoupled || (x >= 2 && y >= 2 && x <= 29 && y <= 29);
            };
            double e = worstError(run, 96, 32 * (k % 3), 32 * (k / 3), 32, 32, expected, inside);
            // The mean colour: what a level-0 filter must not give.
            double fromMean = worstError(
                run, 96, 32 * (k % 3), 32 * (k / 3), 32, 32, [&](int, int) { return mean; },
                inside);
            std::printf("%s, min %s: worst error %.1f levels (%.1f from the mean colour)\n",
                        modeLabel(mode), names[k], e, fromMean);
            // Measured worst: 0.6 levels everywhere but forward's level-0 bilinear (6.1; the
            // decoupled path's, sampled at the same places, 0.2).
            EXPECT_LE(e, !decoupled && k == 1 ? 6.7 : 1.0)
                << modeLabel(mode) << " " << names[k] << ": measured " << e;
            if (level0) { // not the mean a mipmap would give (measured 79.4 and 17.4 levels)
                EXPECT_GE(fromMean, k == 0 ? 71.0 : 15.6)
                    << modeLabel(mode) << " " << names[k] << ": measured " << fromMean;
            }
        }
    }
}

// Five lit quads in a row (grey, rough), the sun shining from the viewer: A single-sided facing
// the camera; B single-sided turned away (a half turn about Y); C double-sided turned away: lit
// as A through its flipped normal; D single-sided mirrored in X (scale -1, 1, 1), still facing
// the camera: drawn as A; E single-sided mirrored in Z, which turns its normal away: culled.
TEST(GltfSamplers, SingleSidedBackFacesAreCulledMirroredInstancesAreNot) {
    nlohmann::json grey = {{"pbrMetallicRoughness",
                            {{"baseColorFactor", {0.6, 0.6, 0.6, 1.0}},
                             {"metallicFactor", 0.0},
                             {"roughnessFactor", 1.0}}}};
    nlohmann::json twoSided = grey;
    twoSided["doubleSided"] = true;
    const nlohmann::json halfTurnY = {0.0, 1.0, 0.0, 0.0};
    std::vector<Quad> quads(5);
    for (int k = 0; k < 5; ++k) quads[size_t(k)].centre = {-5.0f + 2.5f * float(k), 0.0f};
    quads[1].rotation = halfTurnY;
    quads[2].rotation = halfTurnY;
    quads[2].material = 1;
    quads[3].scale = {-1.0, 1.0, 1.0};
    quads[4].scale = {1.0, 1.0, -1.0};
    nlohmann::json sun = {{{"type", "directional"}, {"intensity", 2.0}}};
    std::string file = writeQuads("samplers_culling", quads, {grey, twoSided}, nullptr,
                                  nlohmann::json::array(), 6.5f, 1.3f, sun);
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        RenderRun run = renderOrtho(file, mode, 260, 52);
        const std::vector<uint8_t>& img = run.frames.back().rgba;
        // Each quad's 40 x 40 pixels, less 4 at the border.
        auto stats = [&](int k, double& covered, glm::dvec3& mean) {
            int cx = 130 + int(std::lround((-5.0 + 2.5 * k) * 20.0));
            size_t n = 0, in = 0;
            mean = glm::dvec3(0.0);
            for (int y = 10; y < 42; ++y)
                for (int x = cx - 16; x < cx + 16; ++x, ++n) {
                    const uint8_t* p = &img[(size_t(y) * 260 + size_t(x)) * 4];
                    if (p[3] == 0) continue;
                    ++in;
                    mean += glm::dvec3(p[0], p[1], p[2]);
                }
            covered = double(in) / double(n);
            if (in) mean /= double(in);
        };
        double cov[5];
        glm::dvec3 mean[5];
        for (int k = 0; k < 5; ++k) stats(k, cov[k], mean[k]);
        std::printf("%s: coverage A %.2f B %.2f C %.2f D %.2f E %.2f; mean red A %.1f C %.1f D "
                    "%.1f\n",
                    modeLabel(mode), cov[0], cov[1], cov[2], cov[3], cov[4], mean[0].r, mean[2].r,
                    mean[3].r);
        const char* label = modeLabel(mode);
        EXPECT_EQ(cov[0], 1.0) << label << ": the front-facing single-sided quad";
        EXPECT_EQ(cov[1], 0.0) << label << ": a single-sided quad seen from behind is culled";
        EXPECT_EQ(cov[2], 1.0) << label << ": a double-sided quad seen from behind is drawn";
        EXPECT_EQ(cov[3], 1.0) << label << ": a mirrored instance is not culled inside out";
        EXPECT_EQ(cov[4], 0.0) << label << ": a mirrored instance facing away is culled";
        // Lit from the viewer, A is bright; C (flipped normal) and D light the same.
        EXPECT_GT(mean[0].r, 100.0) << label;
        EXPECT_NEAR(mean[2].r, mean[0].r, 3.0) << label << ": C's normal is flipped to the viewer";
        EXPECT_NEAR(mean[3].r, mean[0].r, 3.0) << label << ": D's normal faces the viewer";
    }
}

// The normal texture's tangent-space normal (0, 0.6, 0.8) (glTF: +Y toward the texture's top, on
// a quad whose texture's top is world +Y) must light the quad as a quad without a normal map
// whose geometry is turned to the world normal (0, 0.6, 0.8): a light from (0, 0.6, 0.8) meets
// both head on. A wrong tangent frame (a flipped bitangent: (0, -0.6, 0.8), n.l = 0.28) or an
// ignored map (n.l = 0.8) darkens the mapped quad only.
TEST(GltfSamplers, NormalMapTiltsTheNormalAsTurnedGeometryDoes) {
    TestTexture tilt{2, std::vector<uint8_t>(2 * 2 * 4)};
    for (int i = 0; i < 4; ++i) { // (n + 1) / 2 of (0, 0.6, 0.8)
        uint8_t* p = &tilt.rgba[size_t(i) * 4];
        p[0] = 128, p[1] = 204, p[2] = 230, p[3] = 255;
    }
    nlohmann::json plain = {{"pbrMetallicRoughness",
                             {{"baseColorFactor", {0.7, 0.7, 0.7, 1.0}},
                              {"metallicFactor", 0.0},
                              {"roughnessFactor", 0.6}}}};
    nlohmann::json mapped = plain;
    mapped["normalTexture"] = {{"index", 0}};
    // Left: the mapped quad facing +Z; right: the plain quad turned about X until its normal is
    // (0, 0.6, 0.8) (a quarter-angle sin/cos of 36.87 degrees / 2).
    const double s = std::sin(-0.5 * std::atan2(0.6, 0.8)),
                 c = std::cos(0.5 * std::atan2(0.6, 0.8));
    std::vector<Quad> quads(2);
    quads[0].centre = {-1.5f, 0.0f};
    quads[1].centre = {1.5f, 0.0f};
    quads[1].material = 1;
    quads[1].rotation = {s, 0.0, 0.0, c};
    // The light's node turned the same way: it travels along -(0, 0.6, 0.8).
    nlohmann::json sun = {{{"type", "directional"}, {"intensity", 2.0}}};
    std::string file = writeQuads("samplers_normal_map", quads, {mapped, plain}, &tilt,
                                  nlohmann::json::array({nlohmann::json::object()}), 3.0f, 1.2f,
                                  sun, nlohmann::json::array({s, 0.0, 0.0, c}));
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        RenderRun run = renderOrtho(file, mode, 200, 80);
        const std::vector<uint8_t>& img = run.frames.back().rgba;
        // The middle 16 x 16 pixels of each quad (33 pixels per world unit).
        auto mean = [&](float x) {
            int cx = 100 + int(std::lround(x * 100.0 / 3.0));
            glm::dvec3 sum(0.0);
            for (int y = 32; y < 48; ++y)
                for (int px = cx - 8; px < cx + 8; ++px) {
                    const uint8_t* p = &img[(size_t(y) * 200 + size_t(px)) * 4];
                    sum += glm::dvec3(p[0], p[1], p[2]);
                }
            return sum / 256.0;
        };
        glm::dvec3 a = mean(-1.5f), b = mean(1.5f);
        const char* label = modeLabel(mode);
        std::printf("[ figures ] normal map %s: mapped quad %.1f, turned quad %.1f (display "
                    "levels, red)\n",
                    label, a.r, b.r);
        EXPECT_GT(b.r, 60.0) << label << ": the turned quad faces the light";
        // Measured 0 levels apart (205 both, either path); the bitangent flipped gave 150.
        EXPECT_NEAR(a.r, b.r, 3.0) << label << ": mapped " << a.r << ", turned " << b.r;
    }
}

// The exposure scales the scene colour before the tone curve (the display encoding of exposure x
// the unlit colour), whether the tonemap runs as its own pass or fused into shading.
TEST(GltfSamplers, ExposureScalesTheSceneColourBeforeTheCurve) {
    const Rgb colour{0.05, 0.12, 0.3};
    nlohmann::json unlit = {
        {"pbrMetallicRoughness", {{"baseColorFactor", {colour.r, colour.g, colour.b, 1.0}}}},
        {"extensions", {{"KHR_materials_unlit", nlohmann::json::object()}}}};
    std::string file = writeQuads("samplers_exposure", {Quad{}}, nlohmann::json::array({unlit}),
                                  nullptr, nlohmann::json::array(), 1.5f, 1.5f);
    const float exposure = 4.0f; // two stops
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled})
        for (bool fuse : {false, true}) {
            RenderOptions o = renderOptions(file, mode, 48, 48);
            o.progress = false;
            o.camera = "ortho";
            o.exposure = exposure;
            o.fuseTonemap = fuse;
            RenderRun run = renderChecked(o);
            std::string label = std::string(modeLabel(mode)) + (fuse ? " fused" : " separate");
            // The middle 16 x 16 pixels (the quad covers 32 x 32).
            double worst = worstError(
                run, 48, 16, 16, 16, 16,
                [&](int, int) {
                    return Rgb{exposure * colour.r, exposure * colour.g, exposure * colour.b};
                },
                [](int, int) { return true; });
            std::printf("[ figures ] exposure x4 %s: largest error %.2f levels\n", label.c_str(),
                        worst);
            // Measured 0.16 levels in every case.
            EXPECT_LE(worst, 0.25) << label;
        }
}
