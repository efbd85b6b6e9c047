#!/usr/bin/env python3
"""Writes the small hand-made glTF files of tests/data/bad/ (malformed, one defect each) and
tests/data/gltf/ (valid edge cases). Run from anywhere; the outputs are checked in.

Each bad file is a valid unit quad with exactly one thing broken, so the error must come from
that defect and nothing else."""
import base64, copy, json, math, os, struct

HERE = os.path.dirname(os.path.abspath(__file__))
BAD = os.path.join(HERE, "bad")
GOOD = os.path.join(HERE, "gltf")


def quad_buffer(positions=None):
    positions = positions or [(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)]
    normals = [(0, 1, 0)] * 4
    uvs = [(0, 0), (1, 0), (1, 1), (0, 1)]
    indices = [0, 1, 2, 0, 2, 3]
    data = b"".join(struct.pack("<3f", *p) for p in positions)      # 0..48
    data += b"".join(struct.pack("<3f", *n) for n in normals)       # 48..96
    data += b"".join(struct.pack("<2f", *t) for t in uvs)           # 96..128
    data += struct.pack("<6H", *indices) + b"\0\0"                  # 128..144
    return data


def data_uri(data):
    return "data:application/octet-stream;base64," + base64.b64encode(data).decode()


def quad(positions=None):
    data = quad_buffer(positions)
    return {
        "asset": {"version": "2.0", "generator": "shadel tests/data/make_test_gltf.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "quad", "mesh": 0}],
        "meshes": [{"name": "quad", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
        "materials": [{"name": "grey", "pbrMetallicRoughness": {
            "baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.7}}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-1, 0, -1], "max": [1, 0, 1]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": 32},
            {"buffer": 0, "byteOffset": 128, "byteLength": 12},
        ],
        "buffers": [{"byteLength": len(data), "uri": data_uri(data)}],
    }


def write(folder, name, doc_or_text):
    path = os.path.join(folder, name)
    mode = "wb" if isinstance(doc_or_text, bytes) else "w"
    with open(path, mode) as f:
        if isinstance(doc_or_text, (dict, list)):
            json.dump(doc_or_text, f, indent=1)
            f.write("\n")
        else:
            f.write(doc_or_text)


def glb(doc, bin_chunk=b"", version=2, length_delta=0):
    js = json.dumps(doc).encode()
    js += b" " * ((4 - len(js) % 4) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js
    if bin_chunk:
        bin_chunk += b"\0" * ((4 - len(bin_chunk) % 4) % 4)
        body += struct.pack("<II", len(bin_chunk), 0x004E4942) + bin_chunk
    return struct.pack("<4sII", b"glTF", version, 12 + len(body) + length_delta) + body


def bad_files():
    out = {}
    q = quad()
    out["broken_json.gltf"] = json.dumps(q)[:200]
    out["root_not_object.gltf"] = "[1, 2, 3]\n"
    out["empty.gltf"] = ""
    out["binary_garbage.gltf"] = bytes((i * 97 + 13) % 256 for i in range(300))

    d = copy.deepcopy(q); d["asset"]["version"] = "1.0"; out["gltf_1_0.gltf"] = d
    d = copy.deepcopy(q); del d["asset"]; out["no_asset.gltf"] = d
    d = copy.deepcopy(q); d["accessors"][0]["count"] = "4"; out["wrong_type_count.gltf"] = d
    d = copy.deepcopy(q); d["meshes"][0]["primitives"] = d["meshes"][0]["primitives"][0]
    out["wrong_type_primitives.gltf"] = d
    d = copy.deepcopy(q); d["scene"] = "hello"; out["wrong_type_scene.gltf"] = d
    d = copy.deepcopy(q); d["materials"][0]["doubleSided"] = "yes"; out["wrong_type_bool.gltf"] = d
    d = copy.deepcopy(q); d["materials"][0]["alphaMode"] = "SOMETIMES"; out["bad_alpha_mode.gltf"] = d
    d = copy.deepcopy(q); d["nodes"][0]["extensions"] = {"EXT_whatever": 5}; out["bad_extension_type.gltf"] = d

    # Index 9001 in a 4-vertex mesh.
    data = bytearray(quad_buffer()); struct.pack_into("<H", data, 128 + 2 * 4, 9001)
    d = copy.deepcopy(q); d["buffers"][0]["uri"] = data_uri(bytes(data)); out["index_out_of_range.gltf"] = d
    d = copy.deepcopy(q); d["accessors"][0]["count"] = 400; out["accessor_out_of_bounds.gltf"] = d
    d = copy.deepcopy(q); d["accessors"][2]["byteOffset"] = 28; out["accessor_offset_out_of_bounds.gltf"] = d
    d = copy.deepcopy(q); d["bufferViews"][2]["byteLength"] = 4000; out["bufferview_out_of_bounds.gltf"] = d
    d = copy.deepcopy(q); d["accessors"][0]["count"] = 4000000000; out["absurd_count.gltf"] = d
    d = copy.deepcopy(q); d["buffers"][0]["uri"] = "does_not_exist.bin"; out["missing_buffer.gltf"] = d
    d = copy.deepcopy(q); d["buffers"][0]["byteLength"] = 400; out["buffer_size_mismatch.gltf"] = d
    d = copy.deepcopy(q); d["bufferViews"][0]["byteStride"] = 6; out["bad_stride.gltf"] = d
    d = copy.deepcopy(q); d["accessors"][3]["componentType"] = 5126; d["accessors"][3]["count"] = 3
    out["float_indices.gltf"] = d
    d = copy.deepcopy(q); d["accessors"][1]["count"] = 3; out["attribute_count_mismatch.gltf"] = d
    d = copy.deepcopy(q); d["accessors"][2]["type"] = "VEC3"; d["accessors"][2]["count"] = 2
    out["attribute_wrong_type.gltf"] = d

    nan = float("nan"); inf = float("inf")
    d = quad([(-1, 0, 1), (1, nan, 1), (1, 0, -1), (-1, 0, -1)]); out["nan_position.gltf"] = d
    d = quad([(-1, 0, 1), (1, 0, 1), (inf, 0, -1), (-1, 0, -1)]); out["inf_position.gltf"] = d
    d = quad([(-1, 0, 1), (1, 0, 1), (7e31, 0, -1), (-1, 0, -1)]); out["huge_coordinates.gltf"] = d
    d = quad(); d["nodes"][0]["camera"] = 0
    d["cameras"] = [{"type": "perspective", "perspective": {"yfov": 5.7, "znear": 0.1}}]
    out["field_of_view_over_pi.gltf"] = d

    d = copy.deepcopy(q); d["nodes"] = [{"children": [1]}, {"children": [0], "mesh": 0}]
    out["cyclic_nodes.gltf"] = d
    d = copy.deepcopy(q); d["nodes"] = [{"children": [0], "mesh": 0}]; out["self_parent_node.gltf"] = d
    d = copy.deepcopy(q); d["nodes"] = [{"children": [2]}, {"children": [2]}, {"mesh": 0}]
    d["scenes"][0]["nodes"] = [0, 1]; out["shared_child_node.gltf"] = d
    d = copy.deepcopy(q); d["scenes"][0]["nodes"] = [0, 0]; out["duplicate_root_node.gltf"] = d

    d = copy.deepcopy(q); del d["nodes"][0]["mesh"]; out["no_triangles_no_mesh.gltf"] = d
    d = copy.deepcopy(q); d["meshes"][0]["primitives"][0]["mode"] = 9; out["bad_mode.gltf"] = d
    d = copy.deepcopy(q); del d["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
    out["no_position.gltf"] = d
    d = copy.deepcopy(q); d["nodes"][0]["mesh"] = 5; out["mesh_index_out_of_range.gltf"] = d
    d = copy.deepcopy(q); d["scene"] = 3; out["scene_index_out_of_range.gltf"] = d
    d = copy.deepcopy(q); d["nodes"][0]["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0]
    out["bad_matrix_size.gltf"] = d
    d = copy.deepcopy(q); d["nodes"][0]["rotation"] = [0, 0, 0, 0]; out["zero_quaternion.gltf"] = d
    text = json.dumps(q).replace('"name": "quad", "mesh": 0', '"name": "quad", "mesh": 0, "translation": [1e400, 0, 0]')
    out["huge_number.gltf"] = text
    d = copy.deepcopy(q); d["nodes"][0]["extensions"] = {"KHR_lights_punctual": {"light": 3}}
    out["light_index_out_of_range.gltf"] = d

    data = quad_buffer()
    g = copy.deepcopy(q); g["buffers"] = [{"byteLength": len(data)}]
    out["truncated.glb"] = glb(g, data)[:-40]
    out["glb_version_1.glb"] = glb(g, data, version=1)
    out["glb_bad_length.glb"] = glb(g, data, length_delta=1000)
    g2 = copy.deepcopy(g); g2["buffers"][0]["byteLength"] = 4096
    out["glb_buffer_too_long.glb"] = glb(g2, data)

    d = quad()
    d["extensionsUsed"] = ["EXT_made_up_geometry", "KHR_lights_punctual"]
    d["extensionsRequired"] = ["KHR_lights_punctual", "EXT_made_up_geometry"]
    out["required_unsupported_extension.gltf"] = d
    return out


def good_files():
    out = {}
    q = quad()
    d = copy.deepcopy(q)
    d["images"] = [{"uri": "missing_texture.png"}]
    d["textures"] = [{"source": 0}]
    d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    out["missing_image.gltf"] = d

    d = copy.deepcopy(q)
    d["extensionsUsed"] = ["EXT_made_up_extension", "KHR_materials_emissive_strength"]
    d["materials"][0]["emissiveFactor"] = [1.0, 0.5, 0.25]
    d["materials"][0]["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}
    d["materials"][0]["extensions"]["EXT_made_up_extension"] = {"anything": [1, 2]}
    out["unsupported_extension.gltf"] = d

    # Optional unsupported extensions in several places (root, node, material, texture info,
    # primitive), some used twice and some missing from extensionsUsed: one warning lists each
    # once.
    d = copy.deepcopy(q)
    d["extensionsUsed"] = ["EXT_made_up_b", "EXT_made_up_a", "KHR_lights_punctual"]
    d["extensions"] = {"EXT_made_up_a": {}}
    d["nodes"][0]["extensions"] = {"EXT_made_up_a": {}, "EXT_made_up_c": {}}
    d["materials"][0]["extensions"] = {"EXT_made_up_b": {}}
    d["meshes"][0]["primitives"][0]["extensions"] = {"EXT_made_up_d": {"x": 1}}
    out["optional_extensions.gltf"] = d

    # Camera and lights on rotated/translated nodes; the expected world values are easy to derive:
    # a -90 degree rotation about X turns the local -Z (view/light direction) into world -Y.
    s = math.sqrt(0.5)
    d = copy.deepcopy(q)
    d["extensionsUsed"] = ["KHR_lights_punctual"]
    d["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "sun", "type": "directional", "color": [1, 0.9, 0.8], "intensity": 3},
        {"name": "bulb", "type": "point", "intensity": 20, "range": 10},
        {"name": "spot", "type": "spot", "intensity": 50, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.4}},
    ]}}
    d["cameras"] = [{"name": "front", "type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1, "zfar": 50}},
                    {"name": "ortho", "type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}]
    d["nodes"] = [
        {"name": "root", "translation": [10, 0, 0], "children": [1, 2, 3, 4, 5, 6]},
        {"name": "quad", "mesh": 0, "scale": [2, 2, 2]},
        {"name": "cam", "camera": 0, "translation": [0, 1, 5]},
        {"name": "sun node", "rotation": [-s, 0, 0, s], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "bulb node", "translation": [0, 3, 0], "extensions": {"KHR_lights_punctual": {"light": 1}}},
        {"name": "spot node", "translation": [1, 4, 0], "rotation": [-s, 0, 0, s],
         "extensions": {"KHR_lights_punctual": {"light": 2}}},
        {"name": "ortho cam", "camera": 1},
    ]
    out["cameras_lights.gltf"] = d

    # Strip of 4 vertices (2 triangles) and a fan of 4 vertices (2 triangles), non-indexed.
    d = copy.deepcopy(q)
    d["meshes"][0]["primitives"] = [
        {"attributes": {"POSITION": 0}, "mode": 5},
        {"attributes": {"POSITION": 0}, "mode": 6},
        {"attributes": {"POSITION": 0}, "mode": 1},
    ]
    out["strip_fan_lines.gltf"] = d

    # Points only (mode 0): no triangles, drawn forward as points (render/points_lines).
    d = copy.deepcopy(q); d["meshes"][0]["primitives"][0]["mode"] = 0; out["points_only.gltf"] = d

    # Mirrored instance: scale -1 in X turns its winding (drawn with the clockwise front face).
    d = copy.deepcopy(q)
    d["nodes"] = [{"name": "normal", "mesh": 0}, {"name": "mirrored", "mesh": 0, "scale": [-1, 1, 1]}]
    d["scenes"][0]["nodes"] = [0, 1]
    out["mirrored.gltf"] = d

    data = quad_buffer()
    g = copy.deepcopy(q); g["buffers"] = [{"byteLength": len(data)}]
    out["quad.glb"] = glb(g, data)
    # quad_meshopt.glb (EXT_meshopt_compression) is not written here: it is
    # `gltfpack -cc -i quad.glb -o quad_meshopt.glb` (Debian's gltfpack 0.18).
    return out


if __name__ == "__main__":
    os.makedirs(BAD, exist_ok=True)
    os.makedirs(GOOD, exist_ok=True)
    for name, content in bad_files().items():
        write(BAD, name, content)
    for name, content in good_files().items():
        write(GOOD, name, content)
