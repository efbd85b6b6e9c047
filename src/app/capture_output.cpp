#include "app/capture_output.h"

#include <cctype>
#include <filesystem>

#include "app/exr_file.h"
#include "app/output_files.h"
#include "core/error.h"
#include "core/log.h"
#include "render/debug/false_colour.h"

namespace shadel {

std::vector<std::string> parseCaptureNames(const std::string& text) {
    std::vector<std::string> names;
    size_t start = 0;
    while (true) {
        size_t comma = text.find(',', start);
        std::string name = text.substr(start, comma == std::string::npos ? comma : comma - start);
        if (name.empty())
            throw InputError(format("--capture %s: empty name (expected NAME[,NAME...]; "
                                    "--capture list prints the names)",
                                    text.c_str()));
        names.push_back(name);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return names;
}

void requireCapturesExist(const CaptureRegistry& registry, const std::vector<std::string>& names) {
    for (const std::string& n : names)
        if (!findCapture(registry, n))
            throw InputError(format("--capture %s: no resource of that name in this frame "
                                    "(available: %s)",
                                    n.c_str(), captureNames(registry).c_str()));
}

std::string captureListing(const CaptureRegistry& registry) {
    std::string out;
    for (const CaptureSource& s : registry.sources)
        out += format("%-18s %s\n", s.name.c_str(), s.what.c_str());
    return out;
}

static bool writesExr(CaptureKind kind) {
    return kind == CaptureKind::Hdr || kind == CaptureKind::Depth;
}

static std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

bool isExrPath(const std::string& path) {
    return lowerExtension(path) == ".exr";
}

std::string imageFormatProblem(const std::string& path) {
    std::string ext = lowerExtension(path);
    if (ext == ".png" || ext == ".exr") return {};
    return ext.empty() ? "no file extension: .png (display colours) or .exr (scene-linear HDR)"
                       : "'" + ext + "' is not an image format shadel writes: .png or .exr";
}

std::string capturePath(const std::string& captureDir, const std::string& out,
                        const std::string& name, CaptureKind kind) {
    std::string file = name + (writesExr(kind) ? ".exr" : ".png");
    if (!captureDir.empty()) return (std::filesystem::path(captureDir) / file).string();
    if (!out.empty() && out.back() == '/') return out + file;
    std::filesystem::path p(out);
    return (p.parent_path() / (p.stem().string() + "." + file)).string();
}

std::vector<std::string> writeCaptures(const CaptureRegistry& registry,
                                       const std::vector<std::string>& names,
                                       const std::string& captureDir, const std::string& out) {
    std::vector<std::string> written;
    for (const std::string& name : names) {
        const CaptureSource* source = findCapture(registry, name);
        if (!source) requireCapturesExist(registry, {name}); // throws
        CapturedImage image = source->read();
        std::string path = capturePath(captureDir, out, name, source->kind);
        if (writesExr(source->kind)) {
            std::vector<uint8_t> exr =
                encodeExr(image.floats, image.width, image.height, image.channels, path);
            writeOutputFile(path, exr.data(), exr.size());
        } else {
            std::vector<uint8_t> rgba = falseColourRgba(image);
            std::vector<uint8_t> png = encodePngRgb(rgba, image.width, image.height);
            writeOutputFile(path, png.data(), png.size());
        }
        SHADEL_INFO("--capture %s: %ux%u -> %s", name.c_str(), image.width, image.height,
                    path.c_str());
        written.push_back(path);
    }
    return written;
}

void writeHdrFrame(const CaptureRegistry& registry, uint32_t ssaa, const std::string& path,
                   const char* capture) {
    const CaptureSource* source = findCapture(registry, capture);
    if (!source) throw InputError(format("--out %s: this frame has no HDR target", path.c_str()));
    CapturedImage hdr = source->read();
    // With TAA the displayed colour is the resolve's (render/taa); alpha stays the scene's.
    if (const CaptureSource* taa = findCapture(registry, "taa")) {
        CapturedImage resolved = taa->read();
        for (size_t i = 0; i < hdr.floats.size() && i < resolved.floats.size(); i += 4)
            for (int c = 0; c < 3; ++c) hdr.floats[i + c] = resolved.floats[i + c];
    }
    uint32_t w = hdr.width / ssaa, h = hdr.height / ssaa;
    std::vector<float> pixels(size_t(w) * h * 4, 0.0f);
    float weight = 1.0f / float(ssaa * ssaa);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
            for (uint32_t sy = 0; sy < ssaa; ++sy)
                for (uint32_t sx = 0; sx < ssaa; ++sx) {
                    size_t src = (size_t(y * ssaa + sy) * hdr.width + x * ssaa + sx) * 4;
                    for (int c = 0; c < 4; ++c)
                        pixels[(size_t(y) * w + x) * 4 + c] += hdr.floats[src + c] * weight;
                }
    std::vector<uint8_t> exr = encodeExr(pixels, w, h, 4, path);
    writeOutputFile(path, exr.data(), exr.size());
}

} // namespace shadel
