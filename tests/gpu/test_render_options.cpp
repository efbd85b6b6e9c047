// runRender's in-code callers (tests, bench) skip the command-line flag checks; the same float
// ranges are enforced on RenderOptions, naming the flag.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "app/cli_validate.h"
#include "app/commands.h"
#include "core/error.h"

using namespace shadel;

TEST(RenderOptionsValidation, DefaultsPassAndBadFloatsNameTheFlag) {
    EXPECT_NO_THROW(validateRenderOptions(RenderOptions{}));
    const float nan = std::nanf("");
    const std::pair<std::function<void(RenderOptions&)>, const char*> cases[] = {
        {[&](RenderOptions& o) { o.exposure = nan; }, "--exposure nan: must be a finite number"},
        {[](RenderOptions& o) { o.exposure = 0; }, "--exposure 0: must be in (0, 1e+06]"},
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
            validateRenderOptions(o);
            ADD_FAILURE() << "accepted: " << message;
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(message, 0), 0u) << e.what();
        }
    }
}
