#pragma once
// `--capture NAME[,NAME...]`: writes named resources of the last frame (render/debug/capture.h)
// to files: EXR for HDR colour and depth, PNG for display formats, false-colour PNG for IDs and
// masks. `--out FILE.exr`: the HDR frame.
#include <string>
#include <vector>

#include "render/debug/capture.h"

namespace shadel {

struct Renderer;

// "a,b" -> {"a", "b"}; throws InputError on an empty name. "list" stays a name.
std::vector<std::string> parseCaptureNames(const std::string& text);
// Throws InputError naming the first name no technique of this frame registered.
void requireCapturesExist(const CaptureRegistry& registry, const std::vector<std::string>& names);
// One line per registered name: "name  what".
std::string captureListing(const CaptureRegistry& registry);

// The file a capture goes to: DIR/NAME.ext with a capture dir, else next to --out
// (out "x/frame.png" -> "x/frame.NAME.ext"; out "x/" -> "x/NAME.ext").
std::string capturePath(const std::string& captureDir, const std::string& out,
                        const std::string& name, CaptureKind kind);
// Reads every named capture and writes it atomically; returns the paths written.
std::vector<std::string> writeCaptures(const CaptureRegistry& registry,
                                       const std::vector<std::string>& names,
                                       const std::string& captureDir, const std::string& out);
// The HDR frame at the output resolution (an N x N SSAA target is box-filtered), as EXR: the
// `capture` named ("hdr": the scene colour).
void writeHdrFrame(const CaptureRegistry& registry, uint32_t ssaa, const std::string& path,
                   const char* capture = "hdr");
bool isExrPath(const std::string& path);
// "" if the extension names a format shadel writes (.png, .exr, any case), else why not.
std::string imageFormatProblem(const std::string& path);

} // namespace shadel
