// runRender's in-code callers (tests, bench) skip the command-line flag checks; the same float
// ranges are enforced on RenderOptions, naming the flag.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <set>

#include "app/cli_validate.h"
#include "app/commands.h"
#include "app/option_table.h"
#include "core/error.h"

using namespace shadel;

TEST(RenderOptionsValidation, DefaultsPassAndBadFloatsNameTheFlag) {
    EXPECT_NO_THROW(validate(RenderOptions{}));
    const float nan = std::nanf("");
    const std::pair<std::function<void(RenderOptions&)>, const char*> cases[] = {
        {[&](RenderOptions& o) { o.exposure = nan; }, "--exposure nan: must be a finite number"},
        // --exposure is in EV: a linear 0 is -inf EV.
        {[](RenderOptions& o) { o.exposure = 0; }, "--exposure -inf: must be a finite number"},
        {[&](RenderOptions& o) { o.shadingBias = nan; }, "--shading-bias nan"},
        {[](RenderOptions& o) { o.trilinearBand = -1; }, "--trilinear-band -1: must be in [0, 1]"},
        {[](RenderOptions& o) { o.shadelsPerMetre = INFINITY; }, "--density inf"},
        {[&](RenderOptions& o) { o.forwardBelowPixels = nan; }, "--forward-below nan"},
        {[](RenderOptions& o) { o.shadelBudget = 0; }, "--shadel-budget 0"},
    };
    for (const auto& [spoil, message] : cases) {
        RenderOptions o;
        spoil(o);
        try {
            validate(o);
            ADD_FAILURE() << "accepted: " << message;
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(message, 0), 0u) << e.what();
        }
    }
}

// Every option of the table reads back what it shows: its default's text parses to the default
// (so --help shows a value the flag accepts), and each flag is declared once.
TEST(RenderOptionsTable, DefaultsRoundTripAndFlagsAreUnique) {
    const RenderSettings defaults;
    std::set<std::string> flags;
    for (const SettingOption& option : settingOptions()) {
        EXPECT_TRUE(flags.insert(option.flag).second) << option.flag << " declared twice";
        EXPECT_EQ(option.check({defaults, true}), "") << option.flag;
        if (option.accepted.empty()) continue; // a flag without a value
        RenderSettings parsed;
        bool sun = true;
        std::string text = option.text({defaults, true});
        EXPECT_NO_THROW(option.parse({parsed, sun}, text)) << option.flag << " " << text;
        EXPECT_EQ(option.json({parsed, sun}), option.json({defaults, true}))
            << option.flag << " " << text;
    }
    EXPECT_GT(flags.size(), 60u);
}

// The generic choice parser: a name gives its value; anything else is one line naming the flag,
// the input and every accepted name.
TEST(RenderOptionsTable, ChoiceParserNamesTheChoices) {
    const Choices<Tonemap> curves = {{"aces-hill", Tonemap::AcesHill}, {"linear", Tonemap::Linear}};
    EXPECT_EQ(parseChoice("--tonemap", "linear", curves), Tonemap::Linear);
    try {
        parseChoice("--tonemap", "Linear", curves);
        ADD_FAILURE() << "accepted Linear";
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "--tonemap Linear: expected aces-hill or linear");
    }
}

// --exposure is in EV: the settings hold 2^EV.
TEST(RenderOptionsTable, ExposureIsInStops) {
    RenderSettings s;
    bool sun = true;
    for (const SettingOption& option : settingOptions())
        if (std::string(option.flag) == "--exposure") option.parse({s, sun}, "-2");
    EXPECT_FLOAT_EQ(s.exposure, 0.25f);
}
