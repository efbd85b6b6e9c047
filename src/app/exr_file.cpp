#include "app/exr_file.h"

#include <cstdlib>
#include <cstring>

#include <tinyexr.h>

#include "core/error.h"
#include "core/log.h"

namespace shadel {

std::vector<uint8_t> encodeExr(const std::vector<float>& pixels, uint32_t width, uint32_t height,
                               uint32_t channels, const std::string& what) {
    if (channels != 1 && channels != 3 && channels != 4)
        throw InputError(
            format("%s: EXR needs 1, 3 or 4 channels, not %u", what.c_str(), channels));
    size_t texels = size_t(width) * height;
    // EXR readers expect channels sorted by name: A, B, G, R (or Z alone).
    static const char* kRgba[] = {"R", "G", "B", "A"};
    std::vector<int> order; // source channel of each stored channel
    if (channels == 1)
        order = {0};
    else if (channels == 3)
        order = {2, 1, 0};
    else
        order = {3, 2, 1, 0};
    std::vector<std::vector<float>> planes(channels, std::vector<float>(texels));
    for (size_t i = 0; i < texels; ++i)
        for (uint32_t c = 0; c < channels; ++c) planes[c][i] = pixels[i * channels + order[c]];
    std::vector<unsigned char*> planePtrs;
    for (auto& p : planes) planePtrs.push_back(reinterpret_cast<unsigned char*>(p.data()));

    EXRHeader header;
    InitEXRHeader(&header);
    EXRImage image;
    InitEXRImage(&image);
    image.num_channels = int(channels);
    image.images = planePtrs.data();
    image.width = int(width);
    image.height = int(height);
    std::vector<EXRChannelInfo> infos(channels);
    for (uint32_t c = 0; c < channels; ++c) {
        std::memset(&infos[c], 0, sizeof(EXRChannelInfo));
        const char* name = channels == 1 ? "Z" : kRgba[order[c]];
        std::strncpy(infos[c].name, name, sizeof(infos[c].name) - 1);
    }
    std::vector<int> types(channels, TINYEXR_PIXELTYPE_FLOAT);
    header.num_channels = int(channels);
    header.channels = infos.data();
    header.pixel_types = types.data();
    header.requested_pixel_types = types.data();
    header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;

    unsigned char* memory = nullptr;
    const char* err = nullptr;
    size_t bytes = SaveEXRImageToMemory(&image, &header, &memory, &err);
    if (bytes == 0) {
        std::string reason = err ? err : "unknown error";
        if (err) FreeEXRErrorMessage(err);
        throw InputError(format("%s: cannot encode EXR (%s)", what.c_str(), reason.c_str()));
    }
    std::vector<uint8_t> out(memory, memory + bytes);
    std::free(memory);
    return out;
}

std::vector<float> decodeExrRgba(const std::vector<uint8_t>& file, uint32_t& width,
                                 uint32_t& height) {
    float* rgba = nullptr;
    int w = 0, h = 0;
    const char* err = nullptr;
    if (LoadEXRFromMemory(&rgba, &w, &h, file.data(), file.size(), &err) != TINYEXR_SUCCESS) {
        std::string reason = err ? err : "unknown error";
        if (err) FreeEXRErrorMessage(err);
        throw InputError(format("cannot decode EXR (%s)", reason.c_str()));
    }
    width = uint32_t(w), height = uint32_t(h);
    std::vector<float> out(rgba, rgba + size_t(w) * h * 4);
    std::free(rgba);
    return out;
}

} // namespace shadel
