#include "apps/cmd_edit.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "volume/core/error.h"

namespace sslpv {

CLI::App* addEditCommand(CLI::App& app, EditArgs& args) {
  CLI::App* cmd = app.add_subcommand("edit", "Paint a scene's material set in the editor window (sslpv-edit)");
  // The editor parses its own options (and --help): everything is passed through.
  cmd->prefix_command();
  cmd->set_help_flag();
  cmd->allow_extras();
  cmd->callback([cmd, &args] { args.forwarded = cmd->remaining(); });
  return cmd;
}

int runEdit(const EditArgs& args) {
  namespace fs = std::filesystem;
  const fs::path editor = fs::read_symlink("/proc/self/exe").parent_path() / "sslpv-edit";
  if (!fs::exists(editor)) {
#ifdef SSLPV_EDITOR_CONFIGURED
    throw ResourceError(editor.string() + " is missing (build the sslpv-edit target)");
#else
    throw ResourceError("this sslpv was configured without VTK, so there is no editor window (install libvtk9-dev "
                        "and re-run cmake); `sslpv paint` applies strokes without it");
#endif
  }
  std::vector<std::string> argStrings{editor.string()};
  argStrings.insert(argStrings.end(), args.forwarded.begin(), args.forwarded.end());
  std::vector<char*> argv;
  for (std::string& a : argStrings) argv.push_back(a.data());
  argv.push_back(nullptr);
  ::execv(argv[0], argv.data());
  throw ResourceError(editor.string() + ": cannot start it: " + std::strerror(errno));
}

}  // namespace sslpv
