// glTF's second UV set in both paths, against a CPU oracle. Unlit quads under an orthographic
// camera, each with two UV sets a quarter turn apart (TEXCOORD_0 runs left to right and top to
// bottom; TEXCOORD_1 = (1 - v0, u0)), show a 4 x 4 palette of distinct colours through nearest
// filtering: every pixel's expected colour is the palette texel at the UV set its material
// names, and the other set gives a different texel everywhere (the oracle's colour from the
// wrong set is reported beside the error, to show the test tells them apart). Quads: the base
// colour on set 1; on set 0; on set 0 turned to set 1 by KHR_texture_transform's texCoord (with
// a scale and offset); on set 1 stored as normalized unsigned bytes; on set 1 of a mesh without
// one (it reads set 0); and alpha-masked on set 1 (a checker of holes: the depth and
// visibility passes' alpha test must read set 1 too, or coverage inverts).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <stb/stb_image_write.h> // defined once, in scene/gltf_import.cpp

#include "gpu_test_env.h"

using namespace shadel;
using namespace shadel::test;

namespace {

constexpr int kQuadPixels = 64; // per quad side: 16 pixels per texel at scale 1
constexpr int kColumns = 3, kRows = 2;

double srgbToLinear(double c8) {
    double c = c8 / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// The display encoding of an unlit colour (shaders/common/tone_curve.glsl displayColor: ACES
// fit, then sRGB), in 8-bit levels.
double displayLevel(double linear) {
    double x = std::max(linear, 0.0);
    double y = std::clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
    double s = y <= 0.0031308 ? y * 12.92 : 1.055 * std::pow(y, 1.0 / 2.4) - 0.055;
    return std::clamp(s, 0.0, 1.0) * 255.0;
}

// Texel (x, y) of the 4 x 4 palette (sRGB, every texel a different colour); `holes` clears the
// alpha of a checker of them (x + y even).
void paletteTexel(int x, int y, bool holes, uint8_t* p) {
    p[0] = uint8_t(40 + 60 * x), p[1] = uint8_t(40 + 60 * y);
    p[2] = uint8_t(((x + 2 * y) % 3) * 90 + 40);
    p[3] = holes && (x + y) % 2 == 0 ? 0 : 255;
}

std::string writePalette(const std::string& name, bool holes) {
    uint8_t rgba[4 * 4 * 4];
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) paletteTexel(x, y, holes, &rgba[(y * 4 + x) * 4]);
    std::string png = tempPath(name + ".png");
    EXPECT_NE(stbi_write_png(png.c_str(), 4, 4, 4, rgba, 16), 0);
    return std::filesystem::path(png).filename().string();
}

// How a quad's material reads the texture.
struct QuadCase {
    const char* label;
    int texCoord = 0;                    // the texture info's
    int transformTexCoord = -1;          // KHR_texture_transform's texCoord (-1: no extension)
    bool uv1Bytes = false;               // TEXCOORD_1 as normalized unsigned bytes (else floats)
    bool noUv1 = false;                  // the mesh has no TEXCOORD_1
    bool masked = false;                 // alpha-masked, on the palette with holes
    int readsSet = 0;                    // the set the oracle samples
    glm::vec2 scale{1.0f}, offset{0.0f}; // the transform's (with transformTexCoord)
};

const QuadCase kCases[kColumns * kRows] = {
    {"set 1", 1, -1, false, false, false, 1},
    {"set 0", 0, -1, false, false, false, 0},
    {"transform texCoord 1", 0, 1, false, false, false, 1, {0.5f, 1.0f}, {0.5f, 0.0f}},
    {"set 1 as bytes", 1, -1, true, false, false, 1},
    {"set 1, mesh without one", 1, -1, false, true, false, 0},
    {"set 1 masked", 1, -1, false, false, true, 1},
};

// The UV sets at a point of a quad, (s, t) in [0, 1] from its top-left corner.
glm::vec2 uvSet(int set, glm::vec2 st) {
    return set == 0 ? st : glm::vec2(1.0f - st.y, st.x);
}

// The palette texel a case samples at (s, t) reading `set`, through its transform.
glm::ivec2 texelAt(const QuadCase& c, int set, glm::vec2 st) {
    glm::vec2 uv = uvSet(set, st);
    if (c.transformTexCoord >= 0) uv = uv * c.scale + c.offset;
    return glm::clamp(glm::ivec2(glm::floor(uv * 4.0f)), glm::ivec2(0), glm::ivec2(3));
}

std::string writeScene() {
    nlohmann::json doc;
    doc["asset"] = {{"version", "2.0"}};
    doc["extensionsUsed"] = {"KHR_materials_unlit", "KHR_texture_transform"};
    doc["scene"] = 0;
    doc["scenes"] = {{{"nodes", nlohmann::json::array()}}};
    std::vector<float> floats;
    std::vector<uint16_t> indices = {0, 1, 2, 0, 2, 3};
    // Corners: bottom-left, bottom-right, top-right, top-left ((s, t) from the top-left).
    const glm::vec2 st[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    for (int k = 0; k < kColumns * kRows; ++k) {
        const QuadCase& c = kCases[k];
        size_t base = floats.size() * 4;
        const float pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
        floats.insert(floats.end(), pos, pos + 12);
        for (int v = 0; v < 4; ++v) floats.insert(floats.end(), {0.0f, 0.0f, 1.0f});
        for (int v = 0; v < 4; ++v) floats.insert(floats.end(), {st[v].x, st[v].y});
        for (int v = 0; v < 4 && !c.noUv1; ++v) {
            glm::vec2 uv1 = uvSet(1, st[v]);
            if (!c.uv1Bytes) {
                floats.insert(floats.end(), {uv1.x, uv1.y});
                continue;
            }
            // Two normalized bytes and two of padding per vertex (4-byte aligned elements).
            uint8_t bytes[4] = {uint8_t(std::lround(uv1.x * 255.0f)),
                                uint8_t(std::lround(uv1.y * 255.0f)), 0, 0};
            float packed;
            std::memcpy(&packed, bytes, 4);
            floats.push_back(packed);
        }
        int view = int(doc["bufferViews"].size()), accessor = int(doc["accessors"].size());
        doc["bufferViews"].push_back(gltfBufferView(base, 48));
        doc["bufferViews"].push_back(gltfBufferView(base + 48, 48));
        doc["bufferViews"].push_back(gltfBufferView(base + 96, 32));
        nlohmann::json position = gltfAccessor(view, 5126, 4, "VEC3");
        position["min"] = {-1, -1, 0};
        position["max"] = {1, 1, 0};
        doc["accessors"].push_back(position);
        doc["accessors"].push_back(gltfAccessor(view + 1, 5126, 4, "VEC3"));
        doc["accessors"].push_back(gltfAccessor(view + 2, 5126, 4, "VEC2"));
        nlohmann::json attributes = {
            {"POSITION", accessor}, {"NORMAL", accessor + 1}, {"TEXCOORD_0", accessor + 2}};
        if (!c.noUv1) {
            nlohmann::json uvView = gltfBufferView(base + 128, c.uv1Bytes ? 16 : 32);
            if (c.uv1Bytes) uvView["byteStride"] = 4;
            doc["bufferViews"].push_back(uvView);
            nlohmann::json uv = gltfAccessor(view + 3, c.uv1Bytes ? 5121 : 5126, 4, "VEC2");
            if (c.uv1Bytes) uv["normalized"] = true;
            doc["accessors"].push_back(uv);
            attributes["TEXCOORD_1"] = accessor + 3;
        }
        nlohmann::json primitive = {
            {"attributes", attributes}, {"indices", 0}, {"material", k}}; // indices: below
        doc["meshes"].push_back({{"primitives", {primitive}}});
        glm::vec2 centre = {-2.0f + 2.0f * float(k % kColumns), 1.0f - 2.0f * float(k / kColumns)};
        doc["scenes"][0]["nodes"].push_back(doc["nodes"].size());
        doc["nodes"].push_back(
            {{"mesh", doc["meshes"].size() - 1}, {"translation", {centre.x, centre.y, 0.0f}}});

        nlohmann::json info = {{"index", c.masked ? 1 : 0}, {"texCoord", c.texCoord}};
        if (c.transformTexCoord >= 0)
            info["extensions"] = {{"KHR_texture_transform",
                                   {{"texCoord", c.transformTexCoord},
                                    {"scale", {c.scale.x, c.scale.y}},
                                    {"offset", {c.offset.x, c.offset.y}}}}};
        nlohmann::json material = {
            {"name", c.label},
            {"pbrMetallicRoughness", {{"baseColorTexture", info}}},
            {"extensions", {{"KHR_materials_unlit", nlohmann::json::object()}}}};
        if (c.masked) material["alphaMode"] = "MASK";
        doc["materials"].push_back(material);
    }
    // The indices follow every quad's floats.
    size_t indexOffset = floats.size() * 4;
    doc["bufferViews"].push_back(gltfBufferView(indexOffset, 12));
    int indexAccessor = int(doc["accessors"].size());
    doc["accessors"].push_back(gltfAccessor(int(doc["bufferViews"].size()) - 1, 5123, 6, "SCALAR"));
    for (auto& mesh : doc["meshes"]) mesh["primitives"][0]["indices"] = indexAccessor;
    doc["images"] = {{{"uri", writePalette("texcoords_palette", false)}},
                     {{"uri", writePalette("texcoords_holes", true)}}};
    doc["samplers"] = {{{"magFilter", 9728}, {"minFilter", 9728}}}; // nearest, level 0
    doc["textures"] = {{{"source", 0}, {"sampler", 0}}, {{"source", 1}, {"sampler", 0}}};
    doc["cameras"] = {
        {{"type", "orthographic"},
         {"orthographic",
          {{"xmag", float(kColumns)}, {"ymag", float(kRows)}, {"znear", 0.1}, {"zfar", 20.0}}}}};
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size());
    doc["nodes"].push_back({{"name", "ortho"}, {"camera", 0}, {"translation", {0.0, 0.0, 5.0}}});
    return writeGltf("texcoords", doc, floats, indices);
}

struct QuadResult {
    double worst = 0.0;         // largest channel error (display levels) against the oracle
    double wrongSet = 0.0;      // mean error against the other set's colours (covered pixels)
    int coverageMismatches = 0; // pixels whose coverage is not the oracle's
    int compared = 0;
};

// Compares quad k's pixels with the oracle, away (3 pixels) from its border and from texel
// edges: decoupled pixels are interpolated between shadels, which a magnified texture shades
// coarser than pixels (render/shadel/texture_rate.h).
QuadResult compareQuad(const std::vector<uint8_t>& img, int width, int k) {
    const QuadCase& c = kCases[k];
    int x0 = kQuadPixels * (k % kColumns), y0 = kQuadPixels * (k / kColumns);
    auto st = [](int x, int y) {
        return glm::vec2((x + 0.5f) / kQuadPixels, (y + 0.5f) / kQuadPixels);
    };
    QuadResult r;
    double wrongSum = 0.0;
    int coloured = 0;
    for (int y = 3; y < kQuadPixels - 3; ++y)
        for (int x = 3; x < kQuadPixels - 3; ++x) {
            glm::ivec2 t = texelAt(c, c.readsSet, st(x, y));
            bool flat = true;
            for (int dy = -3; dy <= 3; ++dy)
                for (int dx = -3; dx <= 3; ++dx)
                    flat = flat && texelAt(c, c.readsSet, st(x + dx, y + dy)) == t;
            if (!flat) continue;
            const uint8_t* p = &img[(size_t(y0 + y) * size_t(width) + size_t(x0 + x)) * 4];
            uint8_t texel[4];
            paletteTexel(t.x, t.y, c.masked, texel);
            bool covered = p[3] != 0, expectCovered = texel[3] != 0;
            if (covered != expectCovered) ++r.coverageMismatches;
            ++r.compared;
            if (!covered || !expectCovered) continue;
            glm::ivec2 w = texelAt(c, 1 - c.readsSet, st(x, y));
            uint8_t wrong[4];
            paletteTexel(w.x, w.y, c.masked, wrong);
            double wrongError = 0.0;
            for (int ch = 0; ch < 3; ++ch) {
                double e = std::abs(p[ch] - displayLevel(srgbToLinear(texel[ch])));
                r.worst = std::max(r.worst, e);
                wrongError += std::abs(p[ch] - displayLevel(srgbToLinear(wrong[ch]))) / 3.0;
            }
            wrongSum += wrongError;
            ++coloured;
        }
    if (coloured > 0) r.wrongSet = wrongSum / coloured;
    return r;
}

} // namespace

TEST(GltfTexcoords, EachSlotSamplesTheUvSetItNames) {
    std::string file = writeScene();
    const int width = kQuadPixels * kColumns, height = kQuadPixels * kRows;
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        RenderOptions o = renderOptions(file, mode, uint32_t(width), uint32_t(height));
        o.progress = false;
        o.camera = "ortho";
        RenderRun run = renderChecked(o);
        const char* label = mode == RenderMode::Forward ? "forward" : "decoupled";
        for (int k = 0; k < kColumns * kRows; ++k) {
            QuadResult r = compareQuad(run.frames.back().rgba, width, k);
            std::printf("%s, %s: worst error %.1f levels over %d pixels (%.1f mean from the "
                        "other set's colours), %d coverage mismatches\n",
                        label, kCases[k].label, r.worst, r.compared, r.wrongSet,
                        r.coverageMismatches);
            EXPECT_GT(r.compared, 1000) << label << " " << kCases[k].label;
            // Measured worst: 0.9 levels (the display encoding's rounding), every case and path.
            EXPECT_LE(r.worst, 1.0) << label << " " << kCases[k].label << ": measured " << r.worst;
            EXPECT_EQ(r.coverageMismatches, 0) << label << " " << kCases[k].label;
            if (kCases[k].noUv1) continue; // both sets are set 0
            // Measured: 65.0 levels (the transformed case), 73.0 (the others).
            EXPECT_GE(r.wrongSet, 58.0)
                << label << " " << kCases[k].label << ": measured " << r.wrongSet;
        }
    }
}
