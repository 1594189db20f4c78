#pragma once
// Subcommand registry: each cmd_<name>.cpp adds itself with
//   EMOFACE_COMMAND(add_info_command)
// where add_info_command(CLI::App& root) creates the subcommand and its
// callback. Callbacks report failure by throwing emoface::Error (exit 2),
// emoface::InputError (exit 2) or emoface::EnvironmentError (exit 3).
#include <CLI/CLI.hpp>

namespace emoface::apps {

using CommandSetup = void (*)(CLI::App& root);

struct CommandRegistration {
    explicit CommandRegistration(CommandSetup setup);
};

// Exit codes shared by every subcommand (README, "Exit codes").
enum ExitCode : int { kExitOk = 0, kExitBadInput = 2, kExitEnvironment = 3 };

}  // namespace emoface::apps

#define EMOFACE_COMMAND_CONCAT2(a, b) a##b
#define EMOFACE_COMMAND_CONCAT(a, b) EMOFACE_COMMAND_CONCAT2(a, b)
#define EMOFACE_COMMAND(setup)                                                   \
    static const ::emoface::apps::CommandRegistration EMOFACE_COMMAND_CONCAT( \
        emoface_command_, __LINE__){setup};
