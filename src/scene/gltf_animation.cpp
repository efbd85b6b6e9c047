#include "scene/gltf_animation.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/error.h"
#include "core/log.h"

namespace shadel {

namespace {

// Elements of an accessor as floats (float, or normalized integer as glTF allows for
// rotations and weights), bounds-checked.
std::vector<float> readAccessor(const tinygltf::Model& model, int index, int components,
                                const std::string& where) {
    if (index < 0 || size_t(index) >= model.accessors.size())
        throw InputError(where + ": accessor index out of range");
    const tinygltf::Accessor& a = model.accessors[size_t(index)];
    int n = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    if (n != components)
        throw InputError(
            where + format(": accessor %d has %d components, expected %d", index, n, components));
    if (a.sparse.isSparse) throw InputError(where + ": sparse animation data is not supported");
    int size = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
    if (size <= 0 || a.bufferView < 0 || size_t(a.bufferView) >= model.bufferViews.size())
        throw InputError(where + format(": accessor %d has no readable data", index));
    const tinygltf::BufferView& v = model.bufferViews[size_t(a.bufferView)];
    const tinygltf::Buffer& b = model.buffers[size_t(v.buffer)];
    size_t element = size_t(size) * size_t(n);
    size_t stride = v.byteStride ? v.byteStride : element;
    uint64_t need =
        uint64_t(a.byteOffset) + uint64_t(stride) * (a.count ? a.count - 1 : 0) + element;
    if (a.count == 0 || need > v.byteLength || v.byteOffset > b.data.size() ||
        v.byteLength > b.data.size() - v.byteOffset)
        throw InputError(where + format(": accessor %d exceeds its buffer view", index));
    const uint8_t* base = b.data.data() + v.byteOffset + a.byteOffset;
    std::vector<float> out(a.count * size_t(n));
    for (size_t i = 0; i < a.count; ++i) {
        for (int c = 0; c < n; ++c) {
            const uint8_t* p = base + i * stride + size_t(c * size);
            float f = 0.0f;
            switch (a.componentType) {
            case TINYGLTF_COMPONENT_TYPE_FLOAT:
                std::memcpy(&f, p, 4);
                break;
            case TINYGLTF_COMPONENT_TYPE_BYTE:
                f = std::max(int8_t(*p) / 127.0f, -1.0f);
                break;
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
                f = *p / 255.0f;
                break;
            case TINYGLTF_COMPONENT_TYPE_SHORT: {
                int16_t s;
                std::memcpy(&s, p, 2);
                f = std::max(s / 32767.0f, -1.0f);
                break;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
                uint16_t s;
                std::memcpy(&s, p, 2);
                f = s / 65535.0f;
                break;
            }
            default:
                throw InputError(where + ": unsupported component type");
            }
            if (!std::isfinite(f)) throw InputError(where + ": value is not finite");
            out[i * size_t(n) + size_t(c)] = f;
        }
    }
    return out;
}

} // namespace

void poseAnimations(tinygltf::Model& model, double time, const std::string& input,
                    const std::function<void(const std::string&)>& warn) {
    for (size_t ai = 0; ai < model.animations.size(); ++ai) {
        const tinygltf::Animation& anim = model.animations[ai];
        for (size_t ci = 0; ci < anim.channels.size(); ++ci) {
            const tinygltf::AnimationChannel& ch = anim.channels[ci];
            std::string where = format("%s: animation %zu channel %zu", input.c_str(), ai, ci);
            if (ch.target_node < 0 || size_t(ch.target_node) >= model.nodes.size()) continue;
            if (ch.sampler < 0 || size_t(ch.sampler) >= anim.samplers.size())
                throw InputError(where + ": sampler index out of range");
            const tinygltf::AnimationSampler& s = anim.samplers[size_t(ch.sampler)];
            tinygltf::Node& node = model.nodes[size_t(ch.target_node)];
            int width = 0;
            if (ch.target_path == "translation" || ch.target_path == "scale")
                width = 3;
            else if (ch.target_path == "rotation")
                width = 4;
            else if (ch.target_path == "weights") {
                const std::vector<double>* defaults = &node.weights;
                if (defaults->empty() && node.mesh >= 0 && size_t(node.mesh) < model.meshes.size())
                    defaults = &model.meshes[size_t(node.mesh)].weights;
                width = int(defaults->size());
                if (width == 0 && node.mesh >= 0 && size_t(node.mesh) < model.meshes.size() &&
                    !model.meshes[size_t(node.mesh)].primitives.empty())
                    width = int(model.meshes[size_t(node.mesh)].primitives[0].targets.size());
                if (width == 0) continue;
            } else {
                continue; // pointer paths of extensions: not animated here
            }
            if (!node.matrix.empty() && width <= 4 && ch.target_path != "weights") {
                warn(where + ": targets a node with a matrix; ignored");
                continue;
            }
            std::vector<float> times = readAccessor(model, s.input, 1, where + " input");
            std::vector<float> values =
                ch.target_path == "weights"
                    ? readAccessor(model, s.output, 1, where + " output")
                    : readAccessor(model, s.output, width, where + " output");
            bool cubic = s.interpolation == "CUBICSPLINE";
            size_t perKey = size_t(width) * (cubic ? 3 : 1);
            if (values.size() != times.size() * perKey)
                throw InputError(where + format(": %zu output values for %zu keys of %zu",
                                                values.size(), times.size(), perKey));
            for (size_t k = 1; k < times.size(); ++k)
                if (!(times[k] > times[k - 1]))
                    throw InputError(where + ": input times must increase");
            // The key interval holding `time` and the position t in it.
            float tq = float(time);
            size_t k0 = 0, k1 = 0;
            float t = 0.0f, dt = 0.0f;
            if (tq <= times.front()) {
                k0 = k1 = 0;
            } else if (tq >= times.back()) {
                k0 = k1 = times.size() - 1;
            } else {
                k1 = size_t(std::upper_bound(times.begin(), times.end(), tq) - times.begin());
                k0 = k1 - 1;
                dt = times[k1] - times[k0];
                t = (tq - times[k0]) / dt;
            }
            auto value = [&](size_t key, size_t c) {
                return values[key * perKey + (cubic ? size_t(width) : 0) + c];
            };
            std::vector<float> out(static_cast<size_t>(width));
            for (size_t c = 0; c < size_t(width); ++c) {
                if (s.interpolation == "STEP" || k0 == k1) {
                    out[c] = value(k0, c);
                } else if (cubic) {
                    float t2 = t * t, t3 = t2 * t;
                    float p0 = value(k0, c), p1 = value(k1, c);
                    float m0 = values[k0 * perKey + 2 * size_t(width) + c] * dt; // out-tangent
                    float m1 = values[k1 * perKey + c] * dt;                     // in-tangent
                    out[c] = (2 * t3 - 3 * t2 + 1) * p0 + (t3 - 2 * t2 + t) * m0 +
                             (-2 * t3 + 3 * t2) * p1 + (t3 - t2) * m1;
                } else {
                    out[c] = value(k0, c) + (value(k1, c) - value(k0, c)) * t;
                }
            }
            if (ch.target_path == "rotation" && s.interpolation == "LINEAR" && k0 != k1) {
                glm::quat a(value(k0, 3), value(k0, 0), value(k0, 1), value(k0, 2));
                glm::quat b(value(k1, 3), value(k1, 0), value(k1, 1), value(k1, 2));
                glm::quat q = glm::slerp(glm::normalize(a), glm::normalize(b), t);
                out = {q.x, q.y, q.z, q.w};
            }
            std::vector<double> asDouble(out.begin(), out.end());
            if (ch.target_path == "translation")
                node.translation = asDouble;
            else if (ch.target_path == "rotation")
                node.rotation = asDouble;
            else if (ch.target_path == "scale")
                node.scale = asDouble;
            else
                node.weights = asDouble;
        }
    }
}

} // namespace shadel
