#pragma once
// The glTF importer's accessor reads: every element bounds-checked against its buffer view and
// buffer, sparse substitutions included. Every failure throws InputError "<input>: <reason>".
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace shadel::gltf {

class AccessorReader {
public:
    AccessorReader(const tinygltf::Model& model, const std::string& input)
        : model_(model), input_(input) {}

    void validateAccessor(int index) { resolveAccessor(index); }
    // Reads an accessor as floats, `components` per element (after checking the type).
    std::vector<float> readFloats(int index, int components, const char* semantic);
    std::vector<uint32_t> readIndices(int index);

private:
    struct AccessorData {
        const uint8_t* base = nullptr; // null: all zeros (no bufferView)
        size_t stride = 0;
        size_t count = 0;
        int components = 0;
        int componentType = 0;
        bool normalized = false;
    };

    const tinygltf::Model& model_;
    const std::string& input_;

    [[noreturn]] void error(const std::string& reason);
    // Resolves an accessor to bytes, checking that every element lies inside its buffer view
    // and buffer. Sparse accessors are checked when read.
    AccessorData resolveAccessor(int index);
    // Calls apply(element, bytes of the value) for each sparse substitution, bounds-checked.
    template <typename F>
    void applySparse(int index, F&& apply);
};

} // namespace shadel::gltf
