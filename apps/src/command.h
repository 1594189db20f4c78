#pragma once
// Subcommand registry: each cmd_<name>.cpp adds itself with
//   EMOFACE_COMMAND(add_info_command)
// where add_info_command(CLI::App& root) creates the subcommand and its
// callback. Callbacks report failure by throwing emoface::InputError (exit 2),
// emoface::EnvironmentError (exit 3) or emoface::InternalError (exit 1); the
// exit codes are emoface::ExitCode (common/error.h, README "Exit codes").
#include <CLI/CLI.hpp>

namespace emoface::apps {

using CommandSetup = void (*)(CLI::App& root);

struct CommandRegistration {
    explicit CommandRegistration(CommandSetup setup);
};

}  // namespace emoface::apps

#define EMOFACE_COMMAND_CONCAT2(a, b) a##b
#define EMOFACE_COMMAND_CONCAT(a, b) EMOFACE_COMMAND_CONCAT2(a, b)
#define EMOFACE_COMMAND(setup)                                                   \
    static const ::emoface::apps::CommandRegistration EMOFACE_COMMAND_CONCAT( \
        emoface_command_, __LINE__){setup};
