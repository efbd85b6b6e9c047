#pragma once
// The glTF importer's inputs: its one error form, reading a file, the GLB container, and the
// callbacks through which tinygltf reads buffers and images (gltf_import.cpp's gate 2).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <tiny_gltf.h>

#include "scene/gltf_uri.h"

namespace shadel::gltf {

// Input files (the .gltf/.glb and every external buffer or image) larger than this are refused:
// the engine has no use for them and it bounds the memory a hostile file can make us allocate.
constexpr uint64_t kMaxFileBytes = 1ull << 30;

constexpr uint32_t kGlbMagic = 0x46546C67; // "glTF"

// Throws InputError "<input>: <reason>".
[[noreturn]] void fail(const std::string& input, const std::string& reason);

// One line, no trailing newline: tinygltf messages end in '\n' and may contain several lines,
// and quote whole data URIs (megabytes of base64), which are abbreviated.
std::string oneLine(std::string text);

std::vector<uint8_t> readWholeFile(const std::string& path, const std::string& input);

uint32_t readU32(const uint8_t* p);

// Returns the JSON text of a .glb (checking the container) or of a .gltf.
std::string_view jsonTextOf(const std::vector<uint8_t>& bytes, bool binary,
                            const std::string& input);

// The same file with its JSON replaced (a .gltf is its JSON; a .glb keeps its other chunks).
std::vector<uint8_t> withJsonText(const std::vector<uint8_t>& bytes, bool binary, std::string text);

// Decodes every image to RGBA8. A broken image is reported and left empty (the material then
// renders without that texture) instead of failing the whole scene.
bool decodeImageToRgba8(tinygltf::Image* image, const int index, std::string*, std::string* warn,
                        int, int, const unsigned char* bytes, int size, void*);

// Where external files may be read from (the fs callbacks' user data).
struct FileAccess {
    std::string modelFolder;
    bool allowExternal = false;
    bool permits(const std::string& path) const {
        return allowExternal || pathInsideFolder(path, modelFolder);
    }
};

// tinygltf's filesystem callbacks (user data: a FileAccess). tinygltf also looks for a relative
// URI in the working directory; outside the model's folder a file does not exist for it (the URI
// check, checkUrisStayInFolder, gives the clear error first).
bool fsFileExists(const std::string& path, void* access);
std::string fsExpandPath(const std::string& path, void*);
bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void* access);
bool fsWriteWholeFile(std::string*, const std::string&, const std::vector<unsigned char>&, void*);

} // namespace shadel::gltf
