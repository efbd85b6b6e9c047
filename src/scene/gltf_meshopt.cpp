#include "scene/gltf_meshopt.h"

#include <cstring>
#include <string_view>

#include <meshoptimizer.h>

#include "core/error.h"
#include "core/log.h"
#include "scene/load_budget.h"

namespace shadel {

namespace {

using json = nlohmann::json;

constexpr const char* kExt = "EXT_meshopt_compression";
constexpr uint64_t kSlack = 1u << 20; // fallback bytes allowed beyond the expansion bound

[[noreturn]] void bad(const std::string& input, const std::string& pointer,
                      const std::string& what) {
    throw InputError(input + ": " + pointer + ": " + what);
}

uint64_t uintMember(const json& obj, const char* key, const std::string& input,
                    const std::string& p, bool required, uint64_t fallback = 0) {
    auto it = obj.find(key);
    if (it == obj.end()) {
        if (required) bad(input, p, format("missing required '%s'", key));
        return fallback;
    }
    if (!it->is_number_unsigned() && !(it->is_number_integer() && it->get<int64_t>() >= 0))
        bad(input, p + "/" + key, "must be a non-negative integer");
    return it->get<uint64_t>();
}

std::string stringMember(const json& obj, const char* key, const std::string& input,
                         const std::string& p, const char* fallback) {
    auto it = obj.find(key);
    if (it == obj.end()) return fallback;
    if (!it->is_string()) bad(input, p + "/" + key, "must be a string");
    return it->get<std::string>();
}

const json* extensionOf(const json& obj) {
    if (!obj.is_object()) return nullptr;
    auto ext = obj.find("extensions");
    if (ext == obj.end() || !ext->is_object()) return nullptr;
    auto e = ext->find(kExt);
    return e == ext->end() ? nullptr : &*e;
}

} // namespace

MeshoptPlan prepareMeshopt(json& document, const std::string& input) {
    MeshoptPlan plan;
    json* buffers = document.contains("buffers") ? &document["buffers"] : nullptr;
    size_t bufferCount = buffers && buffers->is_array() ? buffers->size() : 0;
    uint64_t compressedBytes = 0;
    if (auto views = document.find("bufferViews"); views != document.end() && views->is_array()) {
        for (size_t i = 0; i < views->size(); ++i) {
            const json* e = extensionOf((*views)[i]);
            if (!e) continue;
            std::string p = format("/bufferViews/%zu/extensions/%s", i, kExt);
            uint64_t buffer = uintMember(*e, "buffer", input, p, true);
            if (buffer >= bufferCount)
                bad(input, p + "/buffer",
                    format("index %llu out of range (%zu buffers)", (unsigned long long)buffer,
                           bufferCount));
            uintMember(*e, "byteOffset", input, p, false);
            compressedBytes += uintMember(*e, "byteLength", input, p, true);
            uint64_t stride = uintMember(*e, "byteStride", input, p, true);
            uint64_t count = uintMember(*e, "count", input, p, true);
            std::string mode = stringMember(*e, "mode", input, p, "");
            std::string filter = stringMember(*e, "filter", input, p, "NONE");
            if (mode != "ATTRIBUTES" && mode != "TRIANGLES" && mode != "INDICES")
                bad(input, p + "/mode",
                    "must be ATTRIBUTES, TRIANGLES or INDICES (got '" + mode + "')");
            if (filter != "NONE" && filter != "OCTAHEDRAL" && filter != "QUATERNION" &&
                filter != "EXPONENTIAL")
                bad(input, p + "/filter",
                    "must be NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL (got '" + filter + "')");
            if (mode == "ATTRIBUTES" ? (stride == 0 || stride % 4 != 0 || stride > 256)
                                     : (stride != 2 && stride != 4))
                bad(input, p + "/byteStride",
                    format("%llu is not valid for mode %s", (unsigned long long)stride,
                           mode.c_str()));
            if (mode == "TRIANGLES" && count % 3 != 0)
                bad(input, p + "/count", "must be a multiple of 3 for mode TRIANGLES");
            if (filter != "NONE" && mode != "ATTRIBUTES")
                bad(input, p + "/filter", "filters apply to mode ATTRIBUTES only");
            if (count > (1ull << 28)) bad(input, p + "/count", "out of range");
            plan.any = true;
        }
    }
    uint64_t fallbackBytes = 0;
    for (size_t b = 0; b < bufferCount; ++b) {
        json& buffer = (*buffers)[b];
        const json* e = extensionOf(buffer);
        if (!e) continue;
        std::string p = format("/buffers/%zu/extensions/%s", b, kExt);
        if (!e->is_object()) bad(input, p, "must be an object");
        auto fb = e->find("fallback");
        if (fb != e->end() && !fb->is_boolean()) bad(input, p + "/fallback", "must be a boolean");
        if (fb == e->end() || !fb->get<bool>() || buffer.contains("uri")) continue;
        uint64_t length = uintMember(buffer, "byteLength", input, format("/buffers/%zu", b), true);
        fallbackBytes += length;
        plan.fallbacks.push_back({b, length});
        // tinygltf needs bytes for every buffer of a .gltf: a one-byte placeholder, resized
        // to byteLength after loading.
        buffer["uri"] = "data:application/octet-stream;base64,AA==";
        buffer["byteLength"] = 1;
    }
    uint64_t limit = compressedBytes * kMaxMeshoptExpansion + kSlack;
    if (fallbackBytes > limit)
        throw InputError(format("%s: %s fallback buffers declare %llu bytes for %llu compressed "
                                "bytes (more than %llu:1)",
                                input.c_str(), kExt, (unsigned long long)fallbackBytes,
                                (unsigned long long)compressedBytes,
                                (unsigned long long)kMaxMeshoptExpansion));
    return plan;
}

void decodeMeshopt(const MeshoptPlan& plan, tinygltf::Model& model, const std::string& input) {
    for (const MeshoptPlan::Fallback& f : plan.fallbacks) {
        chargeLoadMemory(f.byteLength, "a meshopt fallback buffer");
        if (f.buffer >= model.buffers.size())
            throw InputError(input + ": " + kExt + ": fallback buffer missing after loading");
        model.buffers[f.buffer].data.assign(size_t(f.byteLength), 0);
    }
    if (!plan.any) return;
    for (size_t i = 0; i < model.bufferViews.size(); ++i) {
        tinygltf::BufferView& view = model.bufferViews[i];
        auto it = view.extensions.find(kExt);
        if (it == view.extensions.end()) continue;
        const tinygltf::Value& e = it->second;
        auto num = [&](const char* key) -> uint64_t {
            return e.Has(key) ? uint64_t(e.Get(key).GetNumberAsDouble()) : 0;
        };
        std::string where = format("/bufferViews/%zu/extensions/%s", i, kExt);
        uint64_t srcBuffer = num("buffer"), srcOffset = num("byteOffset"),
                 srcLength = num("byteLength"), stride = num("byteStride"), count = num("count");
        std::string mode = e.Get("mode").Get<std::string>();
        std::string filter = e.Has("filter") ? e.Get("filter").Get<std::string>() : "NONE";
        const std::vector<unsigned char>& src = model.buffers[size_t(srcBuffer)].data;
        if (srcOffset > src.size() || srcLength > src.size() - srcOffset)
            throw InputError(format("%s: %s: compressed bytes %llu+%llu exceed buffer %llu "
                                    "(%zu bytes)",
                                    input.c_str(), where.c_str(), (unsigned long long)srcOffset,
                                    (unsigned long long)srcLength, (unsigned long long)srcBuffer,
                                    src.size()));
        if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
            throw InputError(format("%s: /bufferViews/%zu: invalid buffer", input.c_str(), i));
        std::vector<unsigned char>& dst = model.buffers[size_t(view.buffer)].data;
        uint64_t bytes = stride * count;
        if (bytes > view.byteLength || view.byteOffset > dst.size() ||
            bytes > dst.size() - view.byteOffset)
            throw InputError(format("%s: %s: %llu x %llu decoded bytes exceed buffer view %zu "
                                    "(%zu bytes) or its buffer",
                                    input.c_str(), where.c_str(), (unsigned long long)count,
                                    (unsigned long long)stride, i, view.byteLength));
        if (srcBuffer == uint64_t(view.buffer) &&
            !(srcOffset + srcLength <= view.byteOffset || view.byteOffset + bytes <= srcOffset))
            throw InputError(format("%s: %s: compressed and decoded bytes overlap", input.c_str(),
                                    where.c_str()));
        // The decoders write whole elements; decode into a scratch copy so a failure leaves
        // nothing half-written and the source may not alias the destination.
        std::vector<unsigned char> out(static_cast<size_t>(bytes));
        const unsigned char* in = src.data() + srcOffset;
        int rc = 0;
        if (mode == "ATTRIBUTES")
            rc = meshopt_decodeVertexBuffer(out.data(), size_t(count), size_t(stride), in,
                                            size_t(srcLength));
        else if (mode == "TRIANGLES")
            rc = meshopt_decodeIndexBuffer(out.data(), size_t(count), size_t(stride), in,
                                           size_t(srcLength));
        else
            rc = meshopt_decodeIndexSequence(out.data(), size_t(count), size_t(stride), in,
                                             size_t(srcLength));
        if (rc != 0)
            throw InputError(format("%s: %s: meshoptimizer could not decode it (error %d)",
                                    input.c_str(), where.c_str(), rc));
        if (filter == "OCTAHEDRAL") {
            if (stride != 4 && stride != 8)
                throw InputError(input + ": " + where + ": OCTAHEDRAL needs byteStride 4 or 8");
            meshopt_decodeFilterOct(out.data(), size_t(count), size_t(stride));
        } else if (filter == "QUATERNION") {
            if (stride != 8)
                throw InputError(input + ": " + where + ": QUATERNION needs byteStride 8");
            meshopt_decodeFilterQuat(out.data(), size_t(count), size_t(stride));
        } else if (filter == "EXPONENTIAL") {
            meshopt_decodeFilterExp(out.data(), size_t(count), size_t(stride));
        }
        if (bytes) std::memcpy(dst.data() + view.byteOffset, out.data(), size_t(bytes));
        // The decoded view is tightly packed at the extension's stride.
        if (mode == "ATTRIBUTES" && view.byteStride == 0 && count > 0) view.byteStride = stride;
    }
}

} // namespace shadel
