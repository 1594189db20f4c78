// emoface: MPEG-4 FAP-driven facial expressions with morphing wrinkles.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "command.h"
#include "emoface/common/error.h"

namespace emoface::apps {
std::vector<CommandSetup>& registered_commands();
}

int main(int argc, char** argv) {
    using namespace emoface::apps;
    CLI::App app{
        "emoface: plays MPEG-4 facial animation (FAP files, or OpenFace and ARKit capture CSVs) and emotion mixtures\n"
        "on a face mesh, with wrinkle maps morphed every frame and bump-mapped.",
        // Named, so usage lines say `emoface play ...`, not argv[0]'s full path.
        "emoface"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "emoface 0.1.0");
    app.add_flag_callback(
        "-v,--verbose", [] { spdlog::set_level(spdlog::level::debug); }, "Print debug messages");
    for (CommandSetup setup : registered_commands()) setup(app);

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // CLI11's own report is two lines and leaves out the command; ours
        // is one ("emoface: play: Could not convert: --fps = x (see ...)").
        std::string command;
        for (const CLI::App* sub : app.get_subcommands()) command = sub->get_name();
        std::string what = e.what();
        for (char& c : what)
            if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
        if (what.size() > 200) what = what.substr(0, 200) + "...";
        std::fprintf(stderr, "emoface: %s%s (see emoface %s--help)\n", command.empty() ? "" : (command + ": ").c_str(),
                     what.c_str(), command.empty() ? "" : (command + " ").c_str());
        return emoface::kExitBadInput;
    } catch (const std::exception& e) {
        // One line; the exit code says whose fault it is (README, "Exit codes").
        std::fprintf(stderr, "emoface: %s\n", emoface::error_line(e).c_str());
        return emoface::exit_code(e);
    } catch (...) {
        std::fprintf(stderr, "emoface: an exception of unknown type (this is a bug)\n");
        return emoface::kExitInternal;
    }
    return emoface::kExitOk;
}
