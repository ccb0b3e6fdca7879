// Issue 26: every integer option of every command, walked from the application `octray`
// itself parses with (make_octray_app), takes decimal digits only within its limits, says
// those limits when it refuses a value, and states them in its help from the same numbers.

#include <gtest/gtest.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "tests/tools/run_octray.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"

namespace {

using octray::testing::run_octray;
using octray::testing::RunResult;
using octray::tools::CommandRunner;
using octray::tools::integer_option_limits;
using octray::tools::integer_range_text;
using octray::tools::IntegerLimits;
using octray::tools::kNoIntegerLimit;
using octray::tools::make_octray_app;

struct IntegerOption {
    std::string command;  // "render"
    std::string name;     // "--spp"
    IntegerLimits limits;
    bool list = false;  // a comma list such as bench --threads 1,2,4
    std::string help;
};

std::vector<IntegerOption> integer_options() {
    CommandRunner run;
    const std::unique_ptr<CLI::App> app = make_octray_app(run);
    std::vector<IntegerOption> out;
    for (CLI::App* command : app->get_subcommands([](CLI::App*) { return true; })) {
        for (CLI::Option* option : command->get_options()) {
            const auto limits = integer_option_limits(*option);
            if (!limits) continue;
            const std::string name = option->get_lnames().empty()
                                         ? "-" + option->get_snames().front()
                                         : "--" + option->get_lnames().front();
            out.push_back({command->get_name(), name, *limits, option->get_delimiter() == ',',
                           option->get_description()});
        }
    }
    return out;
}

// Parses `octray <command> <option> <value>` with a fresh application in this process
// (nothing runs: a command's callback only records its action); the option's canonical
// results, or the parse error's message.
struct ParseOutcome {
    bool ok = false;
    std::vector<std::string> results;
    std::string error;
};

ParseOutcome parse(const IntegerOption& o, const std::string& value) {
    CommandRunner run;
    const std::unique_ptr<CLI::App> app = make_octray_app(run);
    std::vector<std::string> args = {"octray", o.command, o.name, value};
    // A placeholder for each required argument (compare's A and B).
    for (const CLI::Option* option : app->get_subcommand(o.command)->get_options())
        if (option->get_required() && option->get_lnames().empty() &&
            option->get_snames().empty())
            args.push_back("x.exr");
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    ParseOutcome out;
    try {
        app->parse(static_cast<int>(argv.size()), argv.data());
        out.ok = true;
        out.results = app->get_subcommand(o.command)->get_option(o.name)->results();
    } catch (const CLI::ParseError& e) {
        out.error = e.what();
    }
    return out;
}

std::string limits_words(const IntegerLimits& l) {
    return l.hi == kNoIntegerLimit ? "must be an integer >= " + std::to_string(l.lo)
                                   : "must be an integer from " + std::to_string(l.lo) +
                                         " to " + std::to_string(l.hi);
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

class CliOptionsTest : public ::testing::Test {
  protected:
    void SetUp() override {
        // A folder per test: ctest runs the tests of this file side by side.
        dir_ = std::filesystem::path(OCTRAY_TEST_TMPDIR) /
               (std::string("cli_options_test_") +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    // Runs `octray <command> <option> <value>` and checks the refusal: the usage status,
    // the option, its limits and the value given.
    void expect_refused(const IntegerOption& o, const std::string& value,
                        const std::string& shown, bool digits = false) {
        const RunResult r = run_octray({o.command, o.name, value}, dir_);
        const int usage = o.command == "compare" ? 5 : 2;
        EXPECT_EQ(r.status, usage) << o.command << " " << o.name << " '" << value << "'\n"
                                   << r.output;
        EXPECT_TRUE(contains(r.output, o.name + " " + limits_words(o.limits)))
            << o.command << " " << o.name << " '" << value << "'\n"
            << r.output;
        EXPECT_TRUE(contains(r.output, "(got \"" + shown + "\")"))
            << o.command << " " << o.name << " '" << value << "'\n"
            << r.output;
        // Digits out of range need no lesson on digits; anything else gets one.
        EXPECT_EQ(contains(r.output, "decimal digits only"), !digits) << r.output;
        EXPECT_TRUE(std::filesystem::is_empty(dir_)) << "wrote files for " << o.name;
    }

    std::filesystem::path dir_;
};

TEST_F(CliOptionsTest, TheWalkFindsTheIntegerOptionsOfEveryCommand) {
    std::vector<std::string> found;
    for (const IntegerOption& o : integer_options()) found.push_back(o.command + " " + o.name);
    for (const char* expected :
         {"render --width", "render --height", "render --spp", "render --max-depth",
          "render --seed", "render --threads", "render --shard-count", "verify --width",
          "verify --height", "verify --spp", "verify --threads", "bench --threads",
          "bench --reps", "bench --warmup", "bench --width", "bench --height",
          "bench --packet-lanes", "bench --validate-rays"})
        EXPECT_NE(std::find(found.begin(), found.end(), expected), found.end()) << expected;
}

// An integer option added without decimal_integer would escape the walk above: find it by
// "1.5", which CLI11's own conversion to an integer refuses (a ConversionError) while a
// string or real option takes it and a checked option refuses it as a ValidationError.
TEST_F(CliOptionsTest, NoIntegerOptionBypassesTheCheck) {
    CommandRunner run;
    const std::unique_ptr<CLI::App> walk = make_octray_app(run);
    int probed = 0;
    for (CLI::App* command : walk->get_subcommands([](CLI::App*) { return true; })) {
        for (CLI::Option* option : command->get_options()) {
            if (option->get_lnames().empty() || option->get_expected_max() == 0) continue;
            if (integer_option_limits(*option)) continue;
            const std::string name = "--" + option->get_lnames().front();
            CommandRunner fresh_run;
            const std::unique_ptr<CLI::App> app = make_octray_app(fresh_run);
            std::vector<std::string> args = {"octray", command->get_name(), name, "1.5"};
            std::vector<char*> argv;
            for (std::string& a : args) argv.push_back(a.data());
            try {
                app->parse(static_cast<int>(argv.size()), argv.data());
            } catch (const CLI::ConversionError& e) {
                ADD_FAILURE() << command->get_name() << " " << name
                              << " converts to a number without decimal_integer: " << e.what();
            } catch (const CLI::ParseError&) {
                // A checked value (a set of words, a size, a spec): refused by its check.
            }
            ++probed;
        }
    }
    EXPECT_GT(probed, 20);
}

TEST_F(CliOptionsTest, EveryIntegerOptionRefusesAnythingButDecimalDigitsInItsLimits) {
    for (const IntegerOption& o : integer_options()) {
        SCOPED_TRACE(o.command + " " + o.name);
        for (const std::string bad : {"0x10", "+1", " 1", "1e3", "1.0", "-1", "", "1 "})
            expect_refused(o, bad, bad);
        // Just above the upper limit (2^64 for an option that takes any 64-bit value).
        const std::string above = o.limits.hi == std::numeric_limits<std::uint64_t>::max()
                                      ? "18446744073709551616"
                                      : std::to_string(o.limits.hi + 1);
        expect_refused(o, above, above, true);
        if (o.limits.lo > 0)
            expect_refused(o, std::to_string(o.limits.lo - 1), std::to_string(o.limits.lo - 1),
                           true);
        if (o.list) {
            // Each item of a list goes through the same check, with the same message.
            expect_refused(o, std::to_string(o.limits.lo) + ",0x10", "0x10");
            expect_refused(o, std::to_string(o.limits.lo) + "," + above, above, true);
        }
    }
}

TEST_F(CliOptionsTest, EveryIntegerOptionAcceptsItsLimitsInDecimal) {
    for (const IntegerOption& o : integer_options()) {
        SCOPED_TRACE(o.command + " " + o.name);
        for (const std::uint64_t value : {o.limits.lo, o.limits.hi}) {
            const ParseOutcome p = parse(o, std::to_string(value));
            ASSERT_TRUE(p.ok) << p.error;
            EXPECT_EQ(p.results, std::vector<std::string>{std::to_string(value)});
        }
        // Leading zeros are decimal (as in built-in specs and frame lists), never octal.
        const ParseOutcome zeros = parse(o, "0" + std::to_string(o.limits.lo));
        ASSERT_TRUE(zeros.ok) << zeros.error;
        EXPECT_EQ(zeros.results, std::vector<std::string>{std::to_string(o.limits.lo)});
        if (o.list) {
            const ParseOutcome list =
                parse(o, std::to_string(o.limits.lo) + "," + std::to_string(o.limits.hi));
            ASSERT_TRUE(list.ok) << list.error;
            EXPECT_EQ(list.results, (std::vector<std::string>{std::to_string(o.limits.lo),
                                                              std::to_string(o.limits.hi)}));
        }
    }
}

// Help and limits from one place: each integer option's help states the range its check
// enforces, made from the same constants (integer_range_text).
TEST_F(CliOptionsTest, EveryIntegerOptionsHelpStatesItsLimits) {
    for (const IntegerOption& o : integer_options()) {
        const std::string range = integer_range_text(o.limits.lo, o.limits.hi);
        EXPECT_TRUE(contains(o.help, range))
            << o.command << " " << o.name << ": help lacks \"" << range << "\": " << o.help;
    }
    const RunResult help = run_octray({"render", "--help"}, dir_);
    EXPECT_TRUE(contains(help.output, "bounces, 0..64;")) << help.output;
}

// The same for the real options (compare's and verify's thresholds).
TEST_F(CliOptionsTest, EveryRealOptionsHelpStatesItsLimits) {
    CommandRunner run;
    const std::unique_ptr<CLI::App> app = make_octray_app(run);
    int checked = 0;
    for (CLI::App* command : app->get_subcommands([](CLI::App*) { return true; })) {
        for (CLI::Option* option : command->get_options()) {
            const auto range = octray::tools::real_option_range_text(*option);
            if (!range) continue;
            ++checked;
            EXPECT_TRUE(contains(option->get_description(), *range))
                << command->get_name() << " " << option->get_name() << ": help lacks \""
                << *range << "\": " << option->get_description();
        }
    }
    EXPECT_GE(checked, 9);  // compare's six thresholds, verify's three
}

TEST_F(CliOptionsTest, BenchWarmupZeroIsAllowed) {
    for (const IntegerOption& o : integer_options()) {
        if (o.command != "bench" || o.name != "--warmup") continue;
        const ParseOutcome p = parse(o, "0");
        ASSERT_TRUE(p.ok) << p.error;
        EXPECT_EQ(p.results, std::vector<std::string>{"0"});
        return;
    }
    FAIL() << "no bench --warmup";
}

// The tile sizes of render and bench: WxH or N, each side through the same digits-only
// parser, the limits in the message.
TEST_F(CliOptionsTest, TileSizesTakeDecimalDigitsOnly) {
    for (const std::string command : {"render", "bench"}) {
        for (const std::string bad :
             {"0x10", "+8x8", " 8", "8x 8", "1e3", "8x0", "4097x8", "x8"}) {
            const RunResult r = run_octray({command, "--tile", bad}, dir_);
            EXPECT_EQ(r.status, 2) << command << " '" << bad << "'\n" << r.output;
            EXPECT_TRUE(contains(r.output,
                                 "--tile must be WxH or N (NxN) with sides from 1 to "
                                 "4096"))
                << command << " '" << bad << "'\n"
                << r.output;
            EXPECT_TRUE(contains(r.output, "(got \"" + bad + "\")")) << r.output;
        }
    }
    EXPECT_TRUE(std::filesystem::is_empty(dir_));
    CommandRunner run;
    const std::unique_ptr<CLI::App> app = make_octray_app(run);
    std::vector<std::string> args = {"octray", "bench", "--tile", "8,016x4,4096x1"};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    app->parse(static_cast<int>(argv.size()), argv.data());
    EXPECT_EQ(app->get_subcommand("bench")->get_option("--tile")->results(),
              (std::vector<std::string>{"8x8", "16x4", "4096x1"}));
}

// main() parses a command line that starts with a command's name with that command alone
// (make_octray_app's `only`): the same options, help and usage as in the whole
// application. man and completion, which describe every command, and any other first word
// get every command.
TEST(CliApp, ACommandLineThatNamesACommandIsParsedWithThatCommandAlone) {
    const auto all = [](const CLI::App& app) {
        return app.get_subcommands([](const CLI::App*) { return true; });
    };
    CommandRunner run;
    const std::unique_ptr<CLI::App> whole = make_octray_app(run);
    const std::size_t every = all(*whole).size();
    ASSERT_EQ(every, 10u);
    for (const CLI::App* command : all(*whole)) {
        const std::string name = command->get_name();
        SCOPED_TRACE(name);
        CommandRunner own_run;
        const std::unique_ptr<CLI::App> own = make_octray_app(own_run, name);
        if (name == "man" || name == "completion") {
            EXPECT_EQ(all(*own).size(), every);
            continue;
        }
        ASSERT_EQ(all(*own).size(), 1u);
        EXPECT_EQ(all(*own).front()->get_name(), name);
        EXPECT_EQ(all(*own).front()->help(), command->help());
        EXPECT_EQ(all(*own).front()->get_options().size(), command->get_options().size());
    }
    for (const std::string word : {"", "help", "--help", "-V", "frobnicate", "Render"}) {
        CommandRunner own_run;
        EXPECT_EQ(all(*make_octray_app(own_run, word)).size(), every) << word;
    }
}

}  // namespace
