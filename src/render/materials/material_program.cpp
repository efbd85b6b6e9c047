#include "render/materials/material_program.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"

namespace shadel {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr uintmax_t kMaxProgramFileBytes = 1u << 20;
constexpr size_t kMaxStages = 8;
constexpr size_t kMaxParameters = 64;

[[noreturn]] void fail(const std::string& file, const std::string& reason) {
    throw InputError(file + ": " + reason);
}

std::string readText(const std::string& path, const std::string& what) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) fail(path, what + " not found (or not a regular file)");
    if (fs::file_size(path, ec) > kMaxProgramFileBytes) fail(path, what + " larger than 1 MiB");
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    if (!in.good() && !in.eof()) fail(path, "cannot read the " + what);
    return ss.str();
}

bool isIdentifier(const std::string& s) {
    if (s.empty() || s.size() > 64 || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
    for (char c : s)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
    return s.rfind("gl_", 0) != 0 && s.find("__") == std::string::npos;
}

std::vector<uint32_t> parseLayers(const std::string& path, const json& doc) {
    if (!doc.contains("layers") || !doc["layers"].is_array() || doc["layers"].empty())
        fail(path, "\"layers\": expected a non-empty array of layer names (radiance, material)");
    std::set<uint32_t> layers;
    for (const json& l : doc["layers"]) {
        uint32_t index = 0;
        while (index < std::size(kMaterialLayerNames) &&
               (!l.is_string() || l.get<std::string>() != kMaterialLayerNames[index]))
            ++index;
        if (index == std::size(kMaterialLayerNames))
            fail(path, "\"layers\": " + l.dump() + " is not an engine layer (radiance, material)");
        layers.insert(index);
    }
    if (!layers.count(0u))
        fail(path, "\"layers\": must include radiance (reconstruction reads the program's result)");
    return {layers.begin(), layers.end()};
}

std::vector<MaterialParameter> parseParameters(const std::string& path, const json& doc) {
    std::vector<MaterialParameter> out;
    if (!doc.contains("parameters")) return out;
    const json& params = doc["parameters"];
    if (!params.is_object()) fail(path, "\"parameters\": expected an object of name: default");
    if (params.size() > kMaxParameters) fail(path, "\"parameters\": more than 64");
    for (const auto& [name, value] : params.items()) {
        std::string where = "parameter \"" + name + "\": ";
        if (!isIdentifier(name)) fail(path, where + "not a GLSL identifier");
        MaterialParameter p;
        p.name = name;
        std::vector<json> numbers =
            value.is_array() ? value.get<std::vector<json>>() : std::vector<json>{value};
        if (numbers.empty() || numbers.size() > 4)
            fail(path, where + "expected a number or an array of 2 to 4 numbers");
        for (size_t i = 0; i < numbers.size(); ++i) {
            if (!numbers[i].is_number() || !std::isfinite(numbers[i].get<double>()))
                fail(path, where + "expected finite numbers");
            p.value[i] = numbers[i].get<float>();
        }
        if (value.is_array() && numbers.size() == 1)
            fail(path, where + "expected a number or an array of 2 to 4 numbers");
        p.components = uint32_t(numbers.size());
        out.push_back(p);
    }
    return out;
}

std::vector<MaterialStage> parseStages(const std::string& path, const json& doc) {
    if (!doc.contains("stages") || !doc["stages"].is_array() || doc["stages"].empty())
        fail(path, "\"stages\": expected a non-empty array of {\"name\", \"file\"}");
    if (doc["stages"].size() > kMaxStages) fail(path, "\"stages\": more than 8");
    fs::path folder = fs::path(path).parent_path();
    std::vector<MaterialStage> out;
    for (size_t i = 0; i < doc["stages"].size(); ++i) {
        const json& s = doc["stages"][i];
        std::string where = "stages[" + std::to_string(i) + "]";
        if (!s.is_object() || !s.contains("name") || !s["name"].is_string() ||
            !s.contains("file") || !s["file"].is_string())
            fail(path, where + ": expected {\"name\": string, \"file\": string}");
        MaterialStage stage;
        stage.name = s["name"].get<std::string>();
        if (!isIdentifier(stage.name)) fail(path, where + ".name: not an identifier");
        std::string file = s["file"].get<std::string>();
        fs::path rel(file);
        bool escapes = rel.is_absolute() || file.empty();
        for (const fs::path& part : rel) escapes = escapes || part == "..";
        if (escapes)
            fail(path, where + ".file: \"" + file + "\" is not inside the program's folder");
        if (file.find_first_of("\"\\\n") != std::string::npos)
            fail(path, where + ".file: quotes, backslashes and newlines are not allowed");
        stage.path = (folder / rel).lexically_normal().string();
        std::error_code ec;
        if (!fs::is_regular_file(stage.path, ec))
            fail(path, where + ".file: " + stage.path + " not found");
        out.push_back(stage);
    }
    return out;
}

// glslc's output: the first line that names an error, else all of it on one line.
std::string firstError(const std::string& log) {
    std::istringstream in(log);
    std::string line;
    while (std::getline(in, line))
        if (line.find(": error:") != std::string::npos) return line;
    std::string flat = log;
    for (char& c : flat)
        if (c == '\n') c = ' ';
    return flat;
}

std::vector<uint32_t> compileStage(const std::string& source, const std::string& stageFile,
                                   const std::string& includeDir) {
    static uint32_t serial = 0;
    fs::path base = fs::temp_directory_path() / ("shadel-material-" + std::to_string(::getpid()) +
                                                 "-" + std::to_string(serial++));
    std::string src = base.string() + ".comp", spv = base.string() + ".spv",
                log = base.string() + ".log";
    std::string written = writeFileAtomically(src, source.data(), source.size());
    if (!written.empty()) throw InputError(written);
    std::string cmd = "glslc --target-env=vulkan1.3 -O -I '" + includeDir + "' -Werror -o '" + spv +
                      "' '" + src + "' 2>'" + log + "'";
    int status = std::system(cmd.c_str());
    bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    std::vector<uint32_t> code;
    std::string error;
    if (ok) {
        std::ifstream in(spv, std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        code.resize(bytes.size() / 4);
        if (!code.empty()) std::memcpy(code.data(), bytes.data(), code.size() * 4);
        if (code.empty() || code[0] != 0x07230203u) error = stageFile + ": glslc wrote no SPIR-V";
    } else {
        std::ifstream in(log);
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        error = text.empty() ? stageFile + ": glslc failed (is it installed?)" : firstError(text);
    }
    std::error_code ec;
    for (const std::string& p : {src, spv, log}) fs::remove(p, ec);
    if (!error.empty()) throw InputError(error);
    return code;
}

} // namespace

std::string materialProgramFile(const std::string& reference) {
    const std::string prefix = "builtin:";
    if (reference.rfind(prefix, 0) != 0) return reference;
    std::string name = reference.substr(prefix.size());
    if (!isIdentifier(name) && name.find('-') == std::string::npos)
        throw InputError(reference + ": not a built-in material program name");
    return std::string(SHADEL_SHADER_SOURCE_DIR) + "/materials/programs/" + name + ".shmat";
}

MaterialProgram loadMaterialProgram(const std::string& path) {
    if (path.find_first_of("\"\\\n") != std::string::npos)
        fail(path, "quotes, backslashes and newlines are not allowed in a program's path");
    json doc;
    try {
        doc = json::parse(readText(path, "material program"));
    } catch (const json::exception& e) {
        fail(path, std::string("not valid JSON: ") + e.what());
    }
    if (!doc.is_object()) fail(path, "expected a JSON object");
    for (const auto& [key, value] : doc.items())
        if (key != "name" && key != "layers" && key != "parameters" && key != "stages" &&
            key != "common" && key != "rate")
            fail(path,
                 "unknown key \"" + key + "\" (name, layers, parameters, common, rate, stages)");
    MaterialProgram p;
    p.path = path;
    if (!doc.contains("name") || !doc["name"].is_string() ||
        !isIdentifier(doc["name"].get<std::string>()))
        fail(path, "\"name\": expected an identifier string");
    p.name = doc["name"].get<std::string>();
    p.layers = parseLayers(path, doc);
    p.parameters = parseParameters(path, doc);
    p.stages = parseStages(path, doc);
    if (doc.contains("rate")) {
        const json& rate = doc["rate"];
        if (rate != "on_change" && rate != "every_frame")
            fail(path, "\"rate\": expected \"on_change\" or \"every_frame\"");
        p.everyFrame = rate == "every_frame";
    }
    if (doc.contains("common")) {
        json asStage = {{"stages", {{{"name", "common"}, {"file", doc["common"]}}}}};
        if (!doc["common"].is_string()) fail(path, "\"common\": expected a file name");
        try {
            p.common = parseStages(path, asStage)[0].path;
        } catch (const InputError& e) { // named as the key it came from
            std::string what = e.what();
            size_t at = what.find("stages[0].file");
            fail(path, "\"common\"" + (at == std::string::npos ? what : what.substr(at + 14)));
        }
    }
    return p;
}

std::string materialStageSource(const MaterialProgram& program, uint32_t stage) {
    std::ostringstream s;
    s << "#version 460\n#extension GL_GOOGLE_cpp_style_line_directive : require\n";
    s << "#define MATERIAL_STAGE_INDEX " << stage << "u\n";
    s << "#define MATERIAL_STAGE_LAST " << (stage + 1 == program.stages.size() ? 1 : 0) << "\n";
    bool usesMaterialLayer = false;
    for (uint32_t layer : program.layers) usesMaterialLayer = usesMaterialLayer || layer == 1u;
    s << "#define MATERIAL_PROGRAM_WRITES_MATERIAL_LAYER " << (usesMaterialLayer ? 1 : 0) << "\n";
    s << "#include \"materials/program_preamble.glsl\"\n";
    // Errors in the generated declarations (a parameter named like an engine identifier) name
    // the .shmat.
    s << "#line 1 \"" << program.path << "\"\n";
    for (uint32_t layer : program.layers) {
        std::string upper = kMaterialLayerNames[layer];
        for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
        s << "const uint LAYER_" << upper << " = " << layer << "u;\n";
    }
    static const char* const types[] = {"float", "float", "vec2", "vec3", "vec4"};
    s.precision(9);
    for (const MaterialParameter& p : program.parameters) {
        s << "const " << types[p.components] << " " << p.name << " = " << types[p.components]
          << "(";
        for (uint32_t i = 0; i < p.components; ++i)
            s << (i ? ", " : "") << std::showpoint << p.value[i];
        s << ");\n";
    }
    if (!program.common.empty())
        s << "#line 1 \"" << program.common << "\"\n"
          << readText(program.common, "common file") << "\n";
    s << "#define main materialStageMain\n";
    s << "#line 1 \"" << program.stages[stage].path << "\"\n";
    s << readText(program.stages[stage].path, "stage file") << "\n";
    s << "#undef main\n#line 1 \"materials/program_main.glsl\"\n";
    s << "#include \"materials/program_main.glsl\"\n";
    return s.str();
}

std::vector<std::vector<uint32_t>> compileMaterialProgram(const MaterialProgram& program,
                                                          const std::string& shaderSourceDir) {
    std::vector<std::vector<uint32_t>> out;
    for (uint32_t i = 0; i < program.stages.size(); ++i)
        out.push_back(
            compileStage(materialStageSource(program, i), program.stages[i].path, shaderSourceDir));
    return out;
}

} // namespace shadel
