// `morphfem scene-keys`: the scene-key reference (docs/scene-keys.md) on standard output.
#include <iostream>

#include "app/commands.h"
#include "core/command_line.h"
#include "sim/scene_keys.h"

namespace morphfem {

int scene_keys_command(const std::vector<std::string>& args) {
  CommandLine cl("morphfem scene-keys", "",
                 "Prints every key a scene file may hold (path, type, unit, default, range, description) as "
                 "Markdown, from the table the scene readers check against: docs/scene-keys.md is its output.");
  cl.epilog("example: morphfem scene-keys > docs/scene-keys.md");
  if (!cl.parse(args, std::cout)) return 0;
  std::cout << scene_keys_markdown();
  return 0;
}

}  // namespace morphfem
