#pragma once
// Test inputs written as files, shared by several suites: a scene of a sliding cube, a uniform
// environment; and running the shadel binary itself.
#include <array>
#include <string>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace shadel::test {

// A quad (a floor or a wall) and a 1 m cube that an animation slides along a line over 2 s
// (the tests of moving objects: shadows under playback, TAA trails).
struct SlidingCubeScene {
    std::array<glm::vec3, 4> quadCorners; // in the order quadIndices names them
    glm::vec3 quadNormal;
    std::array<uint16_t, 6> quadIndices; // counter-clockwise seen from the lit side
    glm::vec3 cubeFrom, cubeTo;          // the cube's centre at 0 s and at 2 s
    const char* quadName = "quad";
    const char* cubeName = "cube";
    nlohmann::json quadMaterial, cubeMaterial; // glTF materials
};

// Writes the scene as tempPath(NAME.gltf) + NAME.bin; returns the .gltf path.
std::string writeSlidingCubeScene(const std::string& name, const SlidingCubeScene& scene);

// A uniform Radiance .hdr (RGBE, uncompressed scanlines) of `radiance` in every texel, at
// tempPath(NAME.hdr); returns its path.
std::string writeUniformHdr(const std::string& name, float radiance);

// Runs the shadel binary (120 s timeout) with `env` (VAR=value ..., or "") before it; returns
// its exit code, its stderr in `err`.
int runShadel(const std::string& env, const std::string& args, std::string& err);

} // namespace shadel::test
