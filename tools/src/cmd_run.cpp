#include <ostream>

#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {

int cmd_run(const Args&, std::ostream&, std::ostream& err) {
  err << "pbvbus run: scenario runner not built yet\n";
  return 2;
}

}  // namespace pbvbus::tools
