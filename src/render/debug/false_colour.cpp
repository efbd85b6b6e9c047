#include "render/debug/false_colour.h"

#include <algorithm>
#include <cmath>

namespace shadel {

namespace {
uint32_t hashId(uint32_t x) { // lowbias32: neighbouring IDs land far apart
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}
void hsvToRgb(float h, float s, float v, uint8_t rgb[3]) {
    float c = v * s, hp = h * 6.0f, x = c * (1.0f - std::fabs(std::fmod(hp, 2.0f) - 1.0f));
    float r = 0, g = 0, b = 0;
    switch (int(hp) % 6) {
    case 0:
        r = c, g = x;
        break;
    case 1:
        r = x, g = c;
        break;
    case 2:
        g = c, b = x;
        break;
    case 3:
        g = x, b = c;
        break;
    case 4:
        r = x, b = c;
        break;
    default:
        r = c, b = x;
        break;
    }
    float m = v - c;
    rgb[0] = uint8_t(std::lround((r + m) * 255.0f));
    rgb[1] = uint8_t(std::lround((g + m) * 255.0f));
    rgb[2] = uint8_t(std::lround((b + m) * 255.0f));
}
} // namespace

void idColour(uint32_t id, uint8_t rgb[3]) {
    uint32_t h = hashId(id);
    float hue = float(h & 0xFFFFu) / 65536.0f;
    float sat = 0.55f + 0.45f * float((h >> 16) & 0xFFu) / 255.0f;
    float val = 0.7f + 0.3f * float(h >> 24) / 255.0f;
    hsvToRgb(hue, sat, val, rgb);
}

void heatColour(uint32_t value, uint32_t max, uint8_t rgb[3]) {
    if (value == 0) {
        rgb[0] = rgb[1] = rgb[2] = 0;
        return;
    }
    static const float ramp[6][3] = {{0, 0, 1}, {0, 1, 1}, {0, 1, 0},
                                     {1, 1, 0}, {1, 0, 0}, {1, 1, 1}};
    float t = std::clamp(float(value) / float(std::max(max, 1u)), 0.0f, 1.0f) * 5.0f;
    int i = std::min(int(t), 4);
    float f = t - float(i);
    for (int c = 0; c < 3; ++c)
        rgb[c] = uint8_t(std::lround((ramp[i][c] * (1 - f) + ramp[i + 1][c] * f) * 255.0f));
}

std::vector<uint8_t> falseColourRgba(const CapturedImage& image) {
    size_t texels = size_t(image.width) * image.height;
    if (image.kind == CaptureKind::Display) return image.rgba8;
    std::vector<uint8_t> out(texels * 4, 255);
    for (size_t i = 0; i < texels; ++i) {
        uint8_t* p = &out[i * 4];
        switch (image.kind) {
        case CaptureKind::Ids: {
            uint32_t a = image.uints[i * image.channels];
            uint32_t b = image.channels > 1 ? image.uints[i * image.channels + 1] : 0;
            if (a == 0xFFFFFFFFu) { // nothing drawn
                p[0] = p[1] = p[2] = 0;
                p[3] = 0;
            } else {
                idColour(a * 0x9E3779B1u ^ b, p);
            }
            break;
        }
        case CaptureKind::Labels:
            if (image.uints[i] == 0)
                p[0] = p[1] = p[2] = p[3] = 0;
            else
                idColour(image.uints[i], p);
            break;
        case CaptureKind::Mask:
            heatColour(image.uints[i], image.maskMax, p);
            break;
        default: // Hdr, Depth: clamped
            for (uint32_t c = 0; c < 3; ++c) {
                float v = image.floats[i * image.channels + std::min(c, image.channels - 1)];
                p[c] = uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
            }
            break;
        }
    }
    return out;
}

} // namespace shadel
