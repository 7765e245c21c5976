#pragma once
// `sslpv edit SCENE.json [options]`: starts the editor window, sslpv-edit, which lives next
// to this binary (a separate program so that sslpv never loads VTK). Every argument after
// "edit" goes to it unchanged; `sslpv edit --help` lists them.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace sslpv {

struct EditArgs {
  std::vector<std::string> forwarded;
};

CLI::App* addEditCommand(CLI::App& app, EditArgs& args);
/// Replaces this process with sslpv-edit; returns only on failure (ResourceError).
int runEdit(const EditArgs& args);

}  // namespace sslpv
