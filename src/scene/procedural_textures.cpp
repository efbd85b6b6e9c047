#include "scene/procedural_textures.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace shadel {

static uint32_t hash32(uint32_t x) {
    x ^= x >> 16, x *= 0x7feb352du;
    x ^= x >> 15, x *= 0x846ca68bu;
    return x ^ (x >> 16);
}

static float unit(uint32_t h) {
    return float(h >> 8) * (1.0f / 16777216.0f);
}

// Value noise on a lattice of `cell` texels (bilinear between hashed corners).
static float valueNoise(uint32_t x, uint32_t y, uint32_t cell, uint32_t seed) {
    uint32_t cx = x / cell, cy = y / cell;
    float fx = float(x % cell) / float(cell), fy = float(y % cell) / float(cell);
    auto corner = [&](uint32_t i, uint32_t j) {
        return unit(hash32((cx + i) * 73856093u ^ (cy + j) * 19349663u ^ seed));
    };
    float a = corner(0, 0) + (corner(1, 0) - corner(0, 0)) * fx;
    float b = corner(0, 1) + (corner(1, 1) - corner(0, 1)) * fx;
    return a + (b - a) * fy;
}

void generateProceduralTexture(const ProceduralTexture& t, uint32_t size, uint8_t* rgba) {
    uint32_t seed = hash32(t.seed * 2654435761u + t.kind);
    // Two palette colours per texture.
    float hue = unit(hash32(seed ^ 0x1234u));
    auto palette = [&](float shift, float v) {
        float h = std::fmod(hue + shift, 1.0f) * 6.0f;
        float r = std::clamp(std::abs(h - 3.0f) - 1.0f, 0.0f, 1.0f);
        float g = std::clamp(2.0f - std::abs(h - 2.0f), 0.0f, 1.0f);
        float b = std::clamp(2.0f - std::abs(h - 4.0f), 0.0f, 1.0f);
        return std::array<float, 3>{0.15f + 0.8f * r * v, 0.15f + 0.8f * g * v,
                                    0.15f + 0.8f * b * v};
    };
    auto c0 = palette(0.0f, 0.9f), c1 = palette(0.35f, 0.6f);
    // Feature sizes relative to the texture, so a smaller test-scale texture is the same
    // picture at a lower resolution (plus its own texel-level grain).
    uint32_t big = std::max(size / 8, 1u), mid = std::max(size / 64, 1u);
    for (uint32_t y = 0; y < size; ++y) {
        for (uint32_t x = 0; x < size; ++x) {
            float pattern = 0.0f;
            switch (t.kind) {
            case 1: { // tiles with mortar
                uint32_t tx = x / big, ty = y / big;
                bool mortar = (x % big) < big / 16 + 1 || (y % big) < big / 16 + 1;
                pattern = mortar ? 0.1f : 0.4f + 0.6f * unit(hash32(tx * 31u + ty * 977u + seed));
                break;
            }
            case 2: { // rings
                float dx = float(x) / float(size) - 0.5f, dy = float(y) / float(size) - 0.5f;
                pattern = 0.5f + 0.5f * std::sin(std::sqrt(dx * dx + dy * dy) * 80.0f);
                break;
            }
            case 3: // stripes of varying width
                pattern = ((x + y / 2) / mid) % 3 == 0 ? 1.0f : 0.3f;
                break;
            default: // cloudy noise
                pattern = 0.6f * valueNoise(x, y, big, seed) + 0.4f * valueNoise(x, y, mid, seed);
                break;
            }
            // Texel-level grain: what only the finest level holds.
            float grain = unit(hash32(x * 0x27d4eb2du ^ y * 0x165667b1u ^ seed)) - 0.5f;
            float v = std::clamp(pattern + 0.25f * grain, 0.0f, 1.0f);
            uint8_t* p = rgba + (size_t(y) * size + x) * 4;
            for (int c = 0; c < 3; ++c)
                p[c] = uint8_t(
                    std::clamp((c0[c] * v + c1[c] * (1.0f - v)) * 255.0f + 0.5f, 0.0f, 255.0f));
            p[3] = 255;
        }
    }
}

} // namespace shadel
