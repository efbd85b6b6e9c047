#include "scene/gltf_accessors.h"

#include <algorithm>
#include <cstring>

#include "core/error.h"
#include "core/log.h"
#include "scene/gltf_files.h"
#include "scene/load_budget.h"

namespace shadel::gltf {

namespace {

// More elements than this in one accessor is not a scene this engine can render.
constexpr uint64_t kMaxAccessorCount = 1ull << 24;

size_t componentSize(int componentType) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return 4;
    default:
        return 0;
    }
}

const char* typeName(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR:
        return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
        return "VEC2";
    case TINYGLTF_TYPE_VEC3:
        return "VEC3";
    case TINYGLTF_TYPE_VEC4:
        return "VEC4";
    default:
        return "MATRIX";
    }
}

float componentAsFloat(const uint8_t* p, int componentType, bool normalized) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float f;
        std::memcpy(&f, p, 4);
        return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return normalized ? *p / 255.0f : float(*p);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        float v = float(int8_t(*p));
        return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? v / 65535.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::max(v / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return float(v);
    }
    default:
        return 0.0f;
    }
}

uint32_t componentAsUint(const uint8_t* p, int componentType) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
    }
    default:
        return 0;
    }
}

} // namespace

void AccessorReader::error(const std::string& reason) {
    fail(input_, reason);
}

AccessorReader::AccessorData AccessorReader::resolveAccessor(int index) {
    const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
    AccessorData out;
    out.count = acc.count;
    out.components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
    out.componentType = acc.componentType;
    out.normalized = acc.normalized;
    if (acc.count == 0 || acc.count > kMaxAccessorCount)
        error(format("accessor %d count %zu is out of range (limit %llu)", index, acc.count,
                     (unsigned long long)kMaxAccessorCount));
    size_t elementSize = componentSize(acc.componentType) * size_t(out.components);
    if (elementSize == 0) error(format("accessor %d has an invalid component type", index));
    if (acc.bufferView < 0) return out; // zeros, maybe with sparse values on top
    const tinygltf::BufferView& view = model_.bufferViews[size_t(acc.bufferView)];
    const tinygltf::Buffer& buffer = model_.buffers[size_t(view.buffer)];
    if (view.byteOffset > buffer.data.size() ||
        view.byteLength > buffer.data.size() - view.byteOffset)
        error(format("buffer view %d (bytes %zu+%zu) exceeds buffer %d (%zu bytes)", acc.bufferView,
                     view.byteOffset, view.byteLength, view.buffer, buffer.data.size()));
    out.stride = view.byteStride ? view.byteStride : elementSize;
    if (out.stride < elementSize)
        error(format("accessor %d: stride %zu is smaller than its %zu-byte elements", index,
                     out.stride, elementSize));
    uint64_t needed =
        uint64_t(acc.byteOffset) + uint64_t(out.stride) * (acc.count - 1) + elementSize;
    if (acc.byteOffset > view.byteLength || needed > view.byteLength)
        error(format("accessor %d (%zu x %s at offset %zu) exceeds buffer view %d (%zu bytes)",
                     index, acc.count, typeName(acc.type), acc.byteOffset, acc.bufferView,
                     view.byteLength));
    out.base = buffer.data.data() + view.byteOffset + acc.byteOffset;
    return out;
}

template <typename F>
void AccessorReader::applySparse(int index, F&& apply) {
    const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
    if (!acc.sparse.isSparse) return;
    const auto& sparse = acc.sparse;
    size_t count = size_t(sparse.count);
    if (sparse.count <= 0 || count > acc.count)
        error(format("accessor %d: sparse count %d out of range", index, sparse.count));
    size_t indexSize = componentSize(sparse.indices.componentType);
    size_t valueSize = componentSize(acc.componentType) *
                       size_t(tinygltf::GetNumComponentsInType(uint32_t(acc.type)));
    auto slice = [&](int viewIndex, int offset, size_t elementSize) -> const uint8_t* {
        if (viewIndex < 0 || size_t(viewIndex) >= model_.bufferViews.size() || offset < 0)
            error(format("accessor %d: invalid sparse buffer view", index));
        const tinygltf::BufferView& view = model_.bufferViews[size_t(viewIndex)];
        const tinygltf::Buffer& buffer = model_.buffers[size_t(view.buffer)];
        uint64_t end = uint64_t(view.byteOffset) + uint64_t(offset) + uint64_t(elementSize) * count;
        if (view.byteOffset > buffer.data.size() ||
            view.byteLength > buffer.data.size() - view.byteOffset ||
            end > uint64_t(view.byteOffset) + view.byteLength)
            error(format("accessor %d: sparse data exceeds buffer view %d", index, viewIndex));
        return buffer.data.data() + view.byteOffset + size_t(offset);
    };
    const uint8_t* indices = slice(sparse.indices.bufferView, sparse.indices.byteOffset, indexSize);
    const uint8_t* values = slice(sparse.values.bufferView, sparse.values.byteOffset, valueSize);
    for (size_t i = 0; i < count; ++i) {
        uint32_t element = componentAsUint(indices + i * indexSize, sparse.indices.componentType);
        if (element >= acc.count)
            error(format("accessor %d: sparse index %u out of range (count %zu)", index, element,
                         acc.count));
        apply(element, values + i * valueSize);
    }
}

std::vector<float> AccessorReader::readFloats(int index, int components, const char* semantic) {
    const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
    AccessorData a = resolveAccessor(index);
    if (a.components != components)
        error(format("accessor %d (%s) is %s, expected %s", index, semantic, typeName(acc.type),
                     typeName(components == 2   ? TINYGLTF_TYPE_VEC2
                              : components == 3 ? TINYGLTF_TYPE_VEC3
                                                : TINYGLTF_TYPE_VEC4)));
    if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        error(format("accessor %d (%s) has unsigned int components, not allowed for %s", index,
                     semantic, semantic));
    chargeLoadMemory(uint64_t(a.count) * uint64_t(components) * sizeof(float), "an accessor read");
    std::vector<float> out(a.count * size_t(components), 0.0f);
    size_t cs = componentSize(a.componentType);
    if (a.base) {
        for (size_t i = 0; i < a.count; ++i)
            for (int c = 0; c < components; ++c)
                out[i * size_t(components) + size_t(c)] = componentAsFloat(
                    a.base + i * a.stride + size_t(c) * cs, a.componentType, a.normalized);
    }
    applySparse(index, [&](size_t element, const uint8_t* value) {
        for (int c = 0; c < components; ++c)
            out[element * size_t(components) + size_t(c)] =
                componentAsFloat(value + size_t(c) * cs, a.componentType, a.normalized);
    });
    return out;
}

std::vector<uint32_t> AccessorReader::readIndices(int index) {
    const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
    AccessorData a = resolveAccessor(index);
    if (a.components != 1 || (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                              a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                              a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        error(format("accessor %d (indices) must be an unsigned byte/short/int SCALAR (is %s of "
                     "component type %d)",
                     index, typeName(acc.type), acc.componentType));
    chargeLoadMemory(uint64_t(a.count) * sizeof(uint32_t), "an index accessor read");
    std::vector<uint32_t> out(a.count, 0);
    if (a.base)
        for (size_t i = 0; i < a.count; ++i)
            out[i] = componentAsUint(a.base + i * a.stride, a.componentType);
    applySparse(index, [&](size_t element, const uint8_t* value) {
        out[element] = componentAsUint(value, a.componentType);
    });
    return out;
}

} // namespace shadel::gltf
