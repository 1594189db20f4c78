#include "command.h"

#include <vector>

namespace emoface::apps {

std::vector<CommandSetup>& registered_commands() {
    static std::vector<CommandSetup> commands;
    return commands;
}

CommandRegistration::CommandRegistration(CommandSetup setup) {
    registered_commands().push_back(setup);
}

}  // namespace emoface::apps
