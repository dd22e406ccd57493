#include <ostream>

#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {

int cmd_gsd(const Args&, std::ostream&, std::ostream& err) {
  err << "pbvbus gsd: GSD reader not built yet\n";
  return 2;
}

}  // namespace pbvbus::tools
