// Element lookups over pugixml nodes by local name (PLCopen files may prefix their
// elements with a namespace, e.g. xhtml:p), shared by the PLCopen XML readers.
#pragma once

#include <string_view>
#include <vector>

#include <pugixml.hpp>

namespace plcfi::st::xml {

inline std::string_view local_name(const pugi::xml_node& n) {
  std::string_view name = n.name();
  size_t colon = name.find(':');
  return colon == std::string_view::npos ? name : name.substr(colon + 1);
}

inline bool is(const pugi::xml_node& n, std::string_view name) {
  return n.type() == pugi::node_element && local_name(n) == name;
}

// The first child element called `name`; a null node when there is none.
inline pugi::xml_node child(const pugi::xml_node& n, std::string_view name) {
  for (auto c : n.children())
    if (is(c, name)) return c;
  return {};
}

inline std::vector<pugi::xml_node> children(const pugi::xml_node& n, std::string_view name) {
  std::vector<pugi::xml_node> out;
  for (auto c : n.children())
    if (is(c, name)) out.push_back(c);
  return out;
}

inline pugi::xml_node first_element(const pugi::xml_node& n) {
  for (auto c : n.children())
    if (c.type() == pugi::node_element) return c;
  return {};
}

}  // namespace plcfi::st::xml
