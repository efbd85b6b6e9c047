// Transmission (render/transmission, shaders/common/transmission.glsl) judged against analytic
// values: a transmissive slab seen straight on through an orthographic camera, in front of an
// unlit backdrop (its radiance is its base colour), with no light and no environment, so all
// the slab shows is the backdrop it transmits:
// - thin, IOR 1 (no Fresnel): the backdrop times the base colour;
// - thin, IOR 1.5: also times (1 - F0)^2, F0 = 0.04: the light passes two interfaces at normal
//   incidence (the reflected share at the front, and the same share again leaving the back);
// - a volume of thickness d, IOR 1, attenuation colour c at distance D: the backdrop times
//   c^(d / D) per channel (Beer-Lambert: exp(-sigma d) with sigma = -ln(c) / D);
// - a rough thin slab at IOR 1 (no interface: the roughness bends nothing) over a backdrop whose
//   right half is dark: the step behind it as sharp as beside it.
// Forward and decoupled (the backdrop shaded in shadel space, the slab forward after it). The
// tolerance, 0.0075 of the backdrop, is about one and a half 8-bit sRGB levels at these
// radiances: the display quantisation the measurement reads through.
#include "gpu_test_env.h"

#include <cmath>
#include <cstdio>

using namespace shadel;
using namespace shadel::test;
using nlohmann::json;

namespace {

const glm::vec3 kBackdrop(0.8f, 0.6f, 0.45f);

struct Slab {
    glm::vec3 baseColor{1.0f};
    float ior = 1.0f;
    float thickness = 0.0f; // 0: a thin quad; else a box this deep
    glm::vec3 attenuationColor{1.0f};
    float attenuationDistance = 0.0f; // 0: none given
    float roughness = 0.0f;
    bool darkRightHalf = false; // a dark quad over the backdrop's right half (x > 0)
};

const glm::vec3 kDarkBackdrop(0.1f, 0.1f, 0.1f);

void appendMesh(json& doc, std::vector<float>& floats, std::vector<uint16_t>& indices,
                const std::vector<float>& positions, const std::vector<float>& normals,
                const std::vector<uint16_t>& meshIndices, int material) {
    size_t count = positions.size() / 3;
    size_t posOffset = floats.size() * 4;
    floats.insert(floats.end(), positions.begin(), positions.end());
    size_t normalOffset = floats.size() * 4;
    floats.insert(floats.end(), normals.begin(), normals.end());
    int view = int(doc["bufferViews"].size());
    doc["bufferViews"].push_back(gltfBufferView(posOffset, count * 12));
    doc["bufferViews"].push_back(gltfBufferView(normalOffset, count * 12));
    int accessor = int(doc["accessors"].size());
    json position = gltfAccessor(view, 5126, int(count), "VEC3");
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (size_t v = 0; v < count; ++v) {
        glm::vec3 p(positions[v * 3], positions[v * 3 + 1], positions[v * 3 + 2]);
        lo = glm::min(lo, p), hi = glm::max(hi, p);
    }
    position["min"] = {lo.x, lo.y, lo.z};
    position["max"] = {hi.x, hi.y, hi.z};
    doc["accessors"].push_back(position);
    doc["accessors"].push_back(gltfAccessor(view + 1, 5126, int(count), "VEC3"));
    // Indices: a view of their own, placed after every float by writeGltf (patched below).
    json primitive = {{"attributes", {{"POSITION", accessor}, {"NORMAL", accessor + 1}}},
                      {"indices", json{{"first", indices.size()}, {"count", meshIndices.size()}}},
                      {"material", material}};
    indices.insert(indices.end(), meshIndices.begin(), meshIndices.end());
    doc["meshes"].push_back({{"primitives", json::array({primitive})}});
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size());
    doc["nodes"].push_back({{"mesh", doc["meshes"].size() - 1}});
}

// The backdrop (4 x 4 at z = -2) and the slab (1 x 1 centred on the view, its front at z = 0),
// an orthographic camera on +Z seeing 2 x 2 half-extents.
std::string writeSlabScene(const std::string& name, const Slab& slab) {
    json doc;
    doc["asset"] = {{"version", "2.0"}};
    doc["extensionsUsed"] = {"KHR_materials_unlit", "KHR_materials_transmission",
                             "KHR_materials_ior", "KHR_materials_volume"};
    doc["scene"] = 0;
    doc["scenes"] = {{{"nodes", json::array()}}};
    json slabMaterial = {
        {"pbrMetallicRoughness",
         {{"baseColorFactor", {slab.baseColor.r, slab.baseColor.g, slab.baseColor.b, 1.0}},
          {"metallicFactor", 0.0},
          {"roughnessFactor", slab.roughness}}},
        {"extensions",
         {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
          {"KHR_materials_ior", {{"ior", slab.ior}}}}}};
    if (slab.thickness > 0.0f) {
        json volume = {
            {"thicknessFactor", slab.thickness},
            {"attenuationColor",
             {slab.attenuationColor.r, slab.attenuationColor.g, slab.attenuationColor.b}}};
        if (slab.attenuationDistance > 0.0f)
            volume["attenuationDistance"] = slab.attenuationDistance;
        slabMaterial["extensions"]["KHR_materials_volume"] = volume;
    }
    doc["materials"] = {
        {{"pbrMetallicRoughness",
          {{"baseColorFactor", {kBackdrop.r, kBackdrop.g, kBackdrop.b, 1.0}}}},
         {"extensions", {{"KHR_materials_unlit", json::object()}}}},
        slabMaterial,
        {{"pbrMetallicRoughness",
          {{"baseColorFactor", {kDarkBackdrop.r, kDarkBackdrop.g, kDarkBackdrop.b, 1.0}}}},
         {"extensions", {{"KHR_materials_unlit", json::object()}}}}};
    std::vector<float> floats;
    std::vector<uint16_t> indices;
    {
        std::vector<float> p = {-4, -4, -2, 4, -4, -2, 4, 4, -2, -4, 4, -2};
        std::vector<float> n = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
        appendMesh(doc, floats, indices, p, n, {0, 1, 2, 0, 2, 3}, 0);
    }
    if (slab.darkRightHalf) {
        std::vector<float> p = {0, -4, -1.9f, 4, -4, -1.9f, 4, 4, -1.9f, 0, 4, -1.9f};
        std::vector<float> n = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
        appendMesh(doc, floats, indices, p, n, {0, 1, 2, 0, 2, 3}, 2);
    }
    if (slab.thickness > 0.0f) {
        std::vector<float> p, n;
        std::vector<uint16_t> i;
        const float centre[3] = {0.0f, 0.0f, -0.5f * slab.thickness};
        const float half[3] = {0.5f, 0.5f, 0.5f * slab.thickness};
        appendBox(centre, half, p, n, i);
        appendMesh(doc, floats, indices, p, n, i, 1);
    } else {
        std::vector<float> p = {-0.5f, -0.5f, 0, 0.5f, -0.5f, 0, 0.5f, 0.5f, 0, -0.5f, 0.5f, 0};
        std::vector<float> n = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
        appendMesh(doc, floats, indices, p, n, {0, 1, 2, 0, 2, 3}, 1);
    }
    // The index accessors: one view over every index, each primitive an offset into it.
    int indexView = int(doc["bufferViews"].size());
    doc["bufferViews"].push_back(gltfBufferView(floats.size() * 4, indices.size() * 2));
    for (json& mesh : doc["meshes"]) {
        json& primitive = mesh["primitives"][0];
        json range = primitive["indices"];
        json accessor = gltfAccessor(indexView, 5123, range["count"].get<int>(), "SCALAR");
        accessor["byteOffset"] = range["first"].get<size_t>() * 2;
        primitive["indices"] = doc["accessors"].size();
        doc["accessors"].push_back(accessor);
    }
    doc["cameras"] = {
        {{"type", "orthographic"},
         {"orthographic", {{"xmag", 2.0}, {"ymag", 2.0}, {"znear", 0.1}, {"zfar", 20.0}}}}};
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size());
    doc["nodes"].push_back({{"name", "ortho"}, {"camera", 0}, {"translation", {0.0, 0.0, 5.0}}});
    return writeGltf(name, doc, floats, indices);
}

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// The mean linear colour of a square of `half` pixels around (x, y).
glm::vec3 meanLinear(const std::vector<uint8_t>& rgba, uint32_t width, uint32_t x, uint32_t y,
                     uint32_t half) {
    glm::vec3 sum(0.0f);
    int n = 0;
    for (uint32_t py = y - half; py <= y + half; ++py)
        for (uint32_t px = x - half; px <= x + half; ++px, ++n)
            for (int c = 0; c < 3; ++c)
                sum[c] += srgbToLinear(rgba[(size_t(py) * width + px) * 4 + c] / 255.0f);
    return sum / float(n);
}

// The slab scene through its orthographic camera, 96x96, lit by its light alone, linear tone
// curve: the display values are the linear colours (sRGB-encoded).
std::vector<uint8_t> renderSlab(const std::string& name, const Slab& slab, RenderMode mode) {
    RenderOptions o = renderOptions(writeSlabScene(name, slab), mode, 96, 96);
    o.camera = "ortho";
    o.environment = "none";
    o.environmentGiven = true;
    o.addDefaultSun = false;
    o.shadows = false;
    o.tonemap = Tonemap::Linear;
    o.exposure = 1.0f;
    return renderChecked(o).frames[0].rgba;
}

// The slab's colour over the backdrop's, per channel (linear), in `mode`.
glm::vec3 transmittedRatio(const std::string& name, const Slab& slab, RenderMode mode) {
    std::vector<uint8_t> rgba = renderSlab(name, slab, mode);
    // The slab spans the middle quarter (pixels 36..59); the backdrop fills the corners.
    glm::vec3 behind = meanLinear(rgba, 96, 8, 8, 4);
    glm::vec3 through = meanLinear(rgba, 96, 48, 48, 6);
    EXPECT_NEAR(behind.r, kBackdrop.r, 0.01f);
    EXPECT_NEAR(behind.g, kBackdrop.g, 0.01f);
    EXPECT_NEAR(behind.b, kBackdrop.b, 0.01f);
    return through / behind;
}

void expectRatio(glm::vec3 measured, glm::vec3 expected, float tolerance) {
    float worst =
        glm::max(glm::max(std::abs(measured.r - expected.r), std::abs(measured.g - expected.g)),
                 std::abs(measured.b - expected.b));
    std::printf("[ figures ] transmitted ratio %.4f %.4f %.4f, expected %.4f %.4f %.4f, worst "
                "channel off by %.4f\n",
                measured.r, measured.g, measured.b, expected.r, expected.g, expected.b, worst);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(measured[c], expected[c], tolerance)
            << "channel " << c << ": measured " << measured[c] << ", expected " << expected[c];
}

} // namespace

class TransmissionTest : public testing::TestWithParam<RenderMode> {};

TEST_P(TransmissionTest, ThinSlabAtIorOneShowsBackdropTimesBaseColor) {
    Slab slab;
    slab.baseColor = glm::vec3(0.9f, 0.6f, 0.3f);
    glm::vec3 ratio = transmittedRatio("transmission_thin_ior1", slab, GetParam());
    expectRatio(ratio, slab.baseColor, 0.0075f); // measured: 0.0050 off
}

TEST_P(TransmissionTest, ThinSlabAtIorOneAndAHalfLosesFresnelAtTwoInterfaces) {
    Slab slab;
    slab.ior = 1.5f;
    glm::vec3 ratio = transmittedRatio("transmission_thin_ior15", slab, GetParam());
    float expected = (1.0f - 0.04f) * (1.0f - 0.04f);
    expectRatio(ratio, glm::vec3(expected), 0.0075f); // measured: 0.0064 off
}

TEST_P(TransmissionTest, VolumeAttenuatesByBeerLambert) {
    Slab slab;
    slab.thickness = 0.5f;
    slab.attenuationColor = glm::vec3(0.9f, 0.6f, 0.4f);
    slab.attenuationDistance = 0.25f; // two attenuation distances deep
    glm::vec3 ratio = transmittedRatio("transmission_volume", slab, GetParam());
    glm::vec3 expected = glm::pow(slab.attenuationColor, glm::vec3(2.0f));
    expectRatio(ratio, expected, 0.0075f); // measured: 0.0035 off
}

// Either side of the dark half's edge (x = 0, between pixels 47 and 48), columns 44..46 and
// 49..51: behind the slab (rows 47..49) as beside it (rows 11..13), where the backdrop shows.
TEST_P(TransmissionTest, RoughThinSlabAtIorOneKeepsTheBackdropSharp) {
    Slab slab;
    slab.roughness = 0.8f;
    slab.darkRightHalf = true;
    std::vector<uint8_t> rgba = renderSlab("transmission_rough_ior1", slab, GetParam());
    glm::vec3 leftBeside = meanLinear(rgba, 96, 45, 12, 1);
    glm::vec3 rightBeside = meanLinear(rgba, 96, 50, 12, 1);
    glm::vec3 leftBehind = meanLinear(rgba, 96, 45, 48, 1);
    glm::vec3 rightBehind = meanLinear(rgba, 96, 50, 48, 1);
    EXPECT_NEAR(leftBeside.g, kBackdrop.g, 0.01f);
    EXPECT_NEAR(rightBeside.g, kDarkBackdrop.g, 0.01f);
    std::printf("[ figures ] rough slab at IOR 1: green left of the edge %.4f behind / %.4f "
                "beside, right %.4f / %.4f\n",
                leftBehind.g, leftBeside.g, rightBehind.g, rightBeside.g);
    // Measured equal to four digits on both sides, both paths.
    EXPECT_NEAR(leftBehind.g, leftBeside.g, 0.0075f);
    EXPECT_NEAR(rightBehind.g, rightBeside.g, 0.0075f);
}

INSTANTIATE_TEST_SUITE_P(Modes, TransmissionTest,
                         testing::Values(RenderMode::Forward, RenderMode::Decoupled),
                         [](const testing::TestParamInfo<RenderMode>& info) {
                             return info.param == RenderMode::Forward ? "Forward" : "Decoupled";
                         });
