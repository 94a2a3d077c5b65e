// Subcommand registry: each cmd_*.cpp registers a setup function that adds its subcommand to the CLI11 app and
// binds a callback. Callbacks throw farfield::Error for bad input; main() prints "error: ..." and returns 2.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace farfield::app {

using CommandSetup = std::function<void(CLI::App& app)>;

struct CommandRegistry {
  static std::vector<std::pair<std::string, CommandSetup>>& commands() {
    static std::vector<std::pair<std::string, CommandSetup>> list;
    return list;
  }
};

struct RegisterCommand {
  RegisterCommand(const std::string& name, CommandSetup setup) {
    CommandRegistry::commands().emplace_back(name, std::move(setup));
  }
};

}  // namespace farfield::app
