// libFuzzer target: cache files as an attacker or a torn write could leave them. The first input
// byte picks the kind:
//  - a bake cache payload wrapped in a valid header and checksum (so the payload parser and the
//    consistency check against the mesh run on arbitrary bytes, not only the checksum gate);
//  - a whole texture-streaming file (header, directory, level records).
// Every read must return "unusable" with a reason or a result that holds together; a crash, a
// sanitizer report, an exception or a hang (-timeout) is a finding.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include "bake/bake.h"
#include "bake/bake_cache.h"
#include "bake/texture_pack.h"
#include "core/atomic_file.h"
#include "core/log.h"
#include "scene/builtin_gallery.h"
#include "scene/mesh_utils.h"

using namespace shadel;

namespace {

std::string scratchFile(const char* name) {
    static const std::filesystem::path folder = [] {
        auto f = std::filesystem::temp_directory_path() /
                 ("shadel-fuzz-cache-" + std::to_string(getpid()));
        std::filesystem::create_directories(f);
        static const std::filesystem::path removeAtExit = f;
        std::atexit([] {
            std::error_code ec;
            std::filesystem::remove_all(removeAtExit, ec);
        });
        return f;
    }();
    return (folder / name).string();
}

const Mesh& fuzzMesh() {
    static const Mesh mesh = makeBox("fuzz box", {1, 2, 3}, 0);
    return mesh;
}

const Scene& fuzzTextures() {
    static const Scene scene = [] {
        Scene s = makeTextureGallery(16);
        s.textures.resize(2);
        return s;
    }();
    return scene;
}

void writeOrDie(const std::string& path, const std::vector<uint8_t>& bytes) {
    if (!writeFileAtomically(path, bytes.data(), bytes.size()).empty()) std::abort();
}

void fuzzBakePayload(const uint8_t* data, size_t size) {
    const BakeSettings settings;
    const BakeKey key = bakeKey(fuzzMesh(), settings);
    std::string path = scratchFile("bake.bin");
    writeOrDie(path, bakeCacheFileBytes(key, std::vector<uint8_t>(data, data + size)));
    BakedMesh baked;
    std::string why;
    if (readBakeCache(path, key, fuzzMesh(), baked, &why)) {
        // Accepted: it must describe the mesh it claims to.
        if (baked.indices.size() != fuzzMesh().indices.size() || baked.idMaps.empty()) std::abort();
    } else if (why.empty()) {
        std::abort(); // a refusal always says why
    }
}

void fuzzTexturePack(const uint8_t* data, size_t size) {
    const BakeKey key = texturePackKey(fuzzTextures());
    std::string path = scratchFile("textures.bin");
    writeOrDie(path, std::vector<uint8_t>(data, data + size));
    TexturePack pack;
    std::string why;
    if (openTexturePack(path, key, pack, &why)) {
        if (pack.textures.size() != fuzzTextures().textures.size()) std::abort();
    } else if (why.empty()) {
        std::abort();
    }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    setLogLevel(LogLevel::Error);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    if (data[0] & 1)
        fuzzBakePayload(data + 1, size - 1);
    else
        fuzzTexturePack(data + 1, size - 1);
    return 0;
}
