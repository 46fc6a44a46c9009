// Which reader a file goes to, by its extension (case-insensitive, as Windows tools
// write them).
#include "import/import.hpp"

namespace plcfi::st {

InputKind input_kind(std::string_view path) {
  size_t slash = path.find_last_of("/\\");
  std::string_view name = slash == std::string_view::npos ? path : path.substr(slash + 1);
  size_t dot = name.rfind('.');
  if (dot == std::string_view::npos) return InputKind::St;
  std::string ext = canon(name.substr(dot + 1));
  if (ext == "XML") return InputKind::PlcopenXml;
  if (ext == "PLCPROJ" || ext == "TCPOU" || ext == "TCDUT" || ext == "TCGVL" || ext == "TCIO" || ext == "TCTTO")
    return InputKind::TwinCat;
  return InputKind::St;
}

}  // namespace plcfi::st
