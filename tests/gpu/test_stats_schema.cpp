// The `render --stats` JSON against its documented layout, docs/stats.schema.json (explained key
// by key in docs/stats.md): small renders in forward and decoupled mode and with the options
// that add keys are written as a user gets them and validated by an independent JSON Schema
// validator (python3-jsonschema). The schema closes the top level, so a key the writer gains
// without being documented fails here.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "gpu_test_env.h"

#include "app/option_table.h"
#include "app/stats_schema.h"

using namespace shadel;
using shadel::test::renderChecked;
using shadel::test::renderOptions;
using shadel::test::sharedGpu;
using shadel::test::tempPath;

namespace {

const std::string kSchemaPath = std::string(SHADEL_SOURCE_DIR) + "/docs/stats.schema.json";

// Validates with the draft 2020-12 validator; prints every error as "<path>: <message>".
const char* const kValidator = R"(
import json, sys, jsonschema
schema = json.load(open(sys.argv[1]))
stats = json.load(open(sys.argv[2]))
jsonschema.Draft202012Validator.check_schema(schema)
errors = sorted(jsonschema.Draft202012Validator(schema).iter_errors(stats), key=str)
for e in errors:
    print("/".join(str(p) for p in e.absolute_path) + ": " + e.message[:300])
sys.exit(1 if errors else 0)
)";

std::string readText(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

struct Validation {
    int exitCode = -1;
    std::string output; // the validator's messages (stdout and stderr)
};

Validation validateFile(const std::string& statsPath) {
    std::string script = tempPath("stats_schema_validate.py");
    std::ofstream(script) << kValidator;
    std::string out = tempPath("stats_schema_validate.txt");
    std::string cmd =
        "python3 " + script + " " + kSchemaPath + " " + statsPath + " >" + out + " 2>&1";
    int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, readText(out)};
}

Validation validateJson(const nlohmann::json& stats, const std::string& name) {
    std::string path = tempPath(name + ".json");
    std::ofstream(path) << stats.dump(2) << "\n";
    return validateFile(path);
}

bool haveJsonSchema() {
    return std::system("python3 -c 'import jsonschema' >/dev/null 2>&1") == 0;
}

// A small render of `scene` whose stats the render writes to a file, as `--stats` does; the
// table options `flags` ({"--gi", "lpv"}) set on top. Returns the file's JSON.
nlohmann::json renderStats(const std::string& name, RenderOptions o,
                           const std::vector<std::pair<const char*, std::string>>& flags = {}) {
    for (const auto& [flag, text] : flags) parseSetting(flag, text, {o, o.addDefaultSun});
    o.stats = tempPath("stats_schema_" + name + ".json");
    renderChecked(o);
    return nlohmann::json::parse(readText(o.stats));
}

RenderOptions smallOptions(const std::string& scene, RenderMode mode) {
    RenderOptions o = renderOptions(scene, mode, 64, 36);
    o.frames = 2;
    return o;
}

// Validates a written stats file and checks that the keys the run's options are there to add
// are present (so the run covers them).
void expectValidStats(const std::string& name, const nlohmann::json& stats,
                      const std::vector<std::string>& keys) {
    EXPECT_EQ(stats.value("schema", -1), kStatsSchemaVersion) << name;
    for (const std::string& key : keys) EXPECT_TRUE(stats.contains(key)) << name << ": " << key;
    Validation v = validateJson(stats, "stats_schema_checked_" + name);
    EXPECT_EQ(v.exitCode, 0) << name << " stats do not match docs/stats.schema.json:\n" << v.output;
    std::printf("[ figures ] %s: %zu top-level keys, valid\n", name.c_str(), stats.size());
}

void expectValid(const std::string& name, const RenderOptions& o,
                 const std::vector<std::pair<const char*, std::string>>& flags,
                 const std::vector<std::string>& keys) {
    expectValidStats(name, renderStats(name, o, flags), keys);
}

// builtin:default forward, rendered once for the tests that read it.
const nlohmann::json& forwardStats() {
    static const nlohmann::json stats =
        renderStats("forward", smallOptions("builtin:default", RenderMode::Forward));
    return stats;
}

} // namespace

TEST(StatsSchema, ForwardAndDecoupledMatchTheSchema) {
    SHADEL_REQUIRE(haveJsonSchema(), "python3 with jsonschema (scripts/setup.sh)");
    expectValidStats("forward", forwardStats(), {"frame_ms", "passes", "culling", "settings"});
    expectValid("decoupled", smallOptions("builtin:default", RenderMode::Decoupled), {},
                {"marking", "shadels_stored", "shaded_because", "frontend", "view_density"});
}

// Options that add keys: GI, screen-space passes, distance fields, sun cascades, debug lines,
// --inspect, texture streaming with a camera cut, particles, spot shadows and spectra, ray
// tracing (its own test). Not rendered here for their pipelines' cost on lavapipe: decoupled
// spectra (spectra_chunk_*, minutes of pipeline builds), sparse residency and animated playback;
// the schema lists their keys from the writers.
TEST(StatsSchema, FeatureOptionsMatchTheSchema) {
    SHADEL_REQUIRE(haveJsonSchema(), "python3 with jsonschema (scripts/setup.sh)");
    expectValid("features", smallOptions("builtin:default", RenderMode::Forward),
                {{"--gi", "lpv"},
                 {"--screen-space", "on"},
                 {"--distance-fields", "on"},
                 {"--sun-cascades", "3"},
                 {"--debug-lines", "lights"},
                 {"--inspect", "32,18"}},
                {"gi", "tile_classes", "distance_fields", "sun_cascade_splits_m", "debug_lines",
                 "inspect"});
    RenderOptions streamed = smallOptions("builtin:textures", RenderMode::Forward);
    streamed.galleryTextureSize = 256;
    streamed.textureBudgetMiB = 2.0; // above the 1.4 MiB of MIP tails
    streamed.cutCamera = "back";
    streamed.cutFrame = 1;
    expectValid("streaming", streamed, {}, {"texture_streaming", "camera_cut"});
    expectValid("particles", smallOptions("builtin:particles", RenderMode::Forward), {},
                {"particles"});
    expectValid("lights", smallOptions("builtin:lights", RenderMode::Forward),
                {{"--spectra", "on"}}, {"spectra", "tile_features", "spot_shadow_atlas_fill"});
}

// Ray tracing, its terms cached in shadels (decoupled): the BLAS/TLAS counts and "rt".
TEST(StatsSchema, RayTracingMatchesTheSchema) {
    SHADEL_REQUIRE(haveJsonSchema(), "python3 with jsonschema (scripts/setup.sh)");
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery, "a device with ray query");
    expectValid("raytracing", smallOptions("builtin:default", RenderMode::Decoupled),
                {{"--rt-shadows", "on"}, {"--rt-ao", "on"}}, {"rt", "blas_count"});
}

// Temporal anti-aliasing ("taa") and the reference path tracer ("reference", mode reference).
TEST(StatsSchema, TaaAndThePathTracerMatchTheSchema) {
    SHADEL_REQUIRE(haveJsonSchema(), "python3 with jsonschema (scripts/setup.sh)");
    expectValid("taa", smallOptions("builtin:default", RenderMode::Forward), {{"--aa", "taa"}},
                {"taa"});
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery, "a device with ray query");
    expectValid("reference", smallOptions("builtin:cornell", RenderMode::Reference),
                {{"--spp", "1"}}, {"reference"});
}

// The schema must be able to fail: an undocumented key, a missing always-present key and a
// wrong type are each rejected, with the validator naming the key.
TEST(StatsSchema, UndocumentedMissingOrMistypedKeysAreRejected) {
    SHADEL_REQUIRE(haveJsonSchema(), "python3 with jsonschema (scripts/setup.sh)");
    const nlohmann::json& good = forwardStats();
    Validation v = validateJson(good, "stats_schema_good");
    ASSERT_EQ(v.exitCode, 0) << v.output;

    nlohmann::json extra = good;
    extra["frame_ms_undocumented"] = 1.0;
    v = validateJson(extra, "stats_schema_extra");
    EXPECT_EQ(v.exitCode, 1) << v.output;
    EXPECT_NE(v.output.find("frame_ms_undocumented"), std::string::npos) << v.output;

    nlohmann::json nestedExtra = good;
    nestedExtra["pipeline_cache"]["undocumented"] = 0;
    v = validateJson(nestedExtra, "stats_schema_nested_extra");
    EXPECT_EQ(v.exitCode, 1) << v.output;
    EXPECT_NE(v.output.find("undocumented"), std::string::npos) << v.output;

    nlohmann::json missing = good;
    missing.erase("frame_ms");
    v = validateJson(missing, "stats_schema_missing");
    EXPECT_EQ(v.exitCode, 1) << v.output;
    EXPECT_NE(v.output.find("frame_ms"), std::string::npos) << v.output;

    nlohmann::json mistyped = good;
    mistyped["frames"] = "two";
    mistyped["reconstruction_misses"] = -1;
    v = validateJson(mistyped, "stats_schema_mistyped");
    EXPECT_EQ(v.exitCode, 1) << v.output;
    EXPECT_NE(v.output.find("frames: 'two' is not of type 'integer'"), std::string::npos)
        << v.output;
    EXPECT_NE(v.output.find("reconstruction_misses"), std::string::npos) << v.output;

    nlohmann::json otherVersion = good;
    otherVersion["schema"] = kStatsSchemaVersion + 1;
    v = validateJson(otherVersion, "stats_schema_version");
    EXPECT_EQ(v.exitCode, 1) << v.output;
    EXPECT_NE(v.output.find("schema"), std::string::npos) << v.output;
}
