// emoface: MPEG-4 FAP-driven facial expressions with morphing wrinkles.
#include <cstdio>
#include <exception>
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
        "emoface: plays MPEG-4 facial animation (FAP files) and emotion mixtures\n"
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
        app.exit(e);
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
