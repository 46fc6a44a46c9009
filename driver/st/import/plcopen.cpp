// PLCopen TC6 XML 2.01 importer: data types, POUs with ST bodies (CODESYS methods,
// properties and actions too) and configurations become generated ST units whose every
// line points back at the XML text it came from.
//
// Each copied piece of user text (an ST body, a plain-text declaration, a name, an
// initial value) gets its own generated line, so its LineOrigin maps columns exactly,
// entities included (a column map). Lines synthesized from structured elements
// (VAR_INPUT, END_FUNCTION_BLOCK, a task's interval rewritten from PT0.01S) point at the
// element. The XML is read by pugixml; elements are matched by local name, so files with
// the tc6_0201 namespace as a prefix, as the default namespace or without it all read.
#include <pugixml.hpp>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "import/import.hpp"
#include "import/ld.hpp"
#include "import/sfc.hpp"
#include "import/xml_nodes.hpp"

namespace plcfi::st {

namespace {

// The CODESYS addData names (prefix http://www.3s-software.com/plcopenxml/).
constexpr std::string_view kPlainText = "interfaceasplaintext";
// Types, initial values and XML elements nest at most this deep here (pugixml itself
// reads any depth without recursion; our walk recurses).
constexpr int kMaxDepth = 64;

using xml::child;
using xml::children;
using xml::first_element;
using xml::is;
using xml::local_name;

bool attr_true(const pugi::xml_node& n, const char* name) {
  std::string v = n.attribute(name).value();
  return v == "true" || v == "1";
}

// An IEC identifier (letters, digits, '_', not starting with a digit); `dotted` allows
// qualified names (a library namespace, an enumeration value E.V).
bool is_identifier(std::string_view s, bool dotted = false) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  for (char c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && !(dotted && c == '.')) return false;
  return s.back() != '.';
}

// ISO 8601 duration of xsd:duration (PT0.01S, P1DT2H) -> T#0.01s, T#1d2h. Empty when it
// is not one.
std::string iso_to_time_literal(std::string_view s) {
  if (s.size() < 2 || (s[0] != 'P' && s[0] != 'p')) return {};
  std::string out = "T#";
  bool in_time = false, any = false;
  size_t i = 1;
  while (i < s.size()) {
    char c = static_cast<char>(std::toupper(static_cast<unsigned char>(s[i])));
    if (c == 'T') {
      if (in_time) return {};
      in_time = true;
      ++i;
      continue;
    }
    size_t j = i;
    while (j < s.size() && (std::isdigit(static_cast<unsigned char>(s[j])) || s[j] == '.')) ++j;
    if (j == i || j == s.size() || j - i > 30) return {};
    std::string_view number = s.substr(i, j - i);
    if (number.front() == '.' || number.back() == '.' || std::count(number.begin(), number.end(), '.') > 1) return {};
    char unit = static_cast<char>(std::toupper(static_cast<unsigned char>(s[j])));
    const char* st_unit = nullptr;
    if (!in_time && unit == 'D') st_unit = "d";
    else if (in_time && unit == 'H') st_unit = "h";
    else if (in_time && unit == 'M') st_unit = "m";
    else if (in_time && unit == 'S') st_unit = "s";
    if (!st_unit) return {};
    out += std::string(number) + st_unit;
    any = true;
    i = j + 1;
  }
  return any ? out : std::string{};
}

size_t utf8_length(unsigned long cp) { return cp < 0x80 ? 1 : cp < 0x800 ? 2 : cp < 0x10000 ? 3 : 4; }

// Length of the character reference or predefined entity at raw[r] ('&'), and of its
// replacement text in bytes; 0 when it is none (pugixml leaves those as they are).
size_t entity_at(std::string_view raw, size_t r, size_t* decoded) {
  size_t semi = raw.find(';', r);
  if (semi == std::string_view::npos || semi - r > 12) return 0;
  std::string_view name = raw.substr(r + 1, semi - r - 1);
  if (name == "lt" || name == "gt" || name == "amp" || name == "quot" || name == "apos") {
    *decoded = 1;
    return semi - r + 1;
  }
  if (name.size() >= 2 && name[0] == '#') {
    unsigned long cp = 0;
    bool hex = name[1] == 'x';
    std::string_view digits = name.substr(hex ? 2 : 1);
    if (digits.empty()) return 0;
    for (char c : digits) {
      int d = std::isdigit(static_cast<unsigned char>(c)) ? c - '0'
              : hex && std::isxdigit(static_cast<unsigned char>(c)) ? std::tolower(static_cast<unsigned char>(c)) - 'a' + 10
                                                                    : -1;
      if (d < 0) return 0;
      cp = cp * (hex ? 16 : 10) + static_cast<unsigned long>(d);
      if (cp > 0x10FFFF) return 0;
    }
    *decoded = utf8_length(cp);
    return semi - r + 1;
  }
  return 0;
}

// A piece of user text as pugixml decoded it, with the file offset of each byte (an
// entity's bytes all point at its '&'); exact is false when the text could not be
// aligned with the file, and then every byte points at the piece's start.
struct Copy {
  std::string text;
  std::vector<uint32_t> pos;
  bool exact = true;

  void append(std::string_view value, std::string_view raw, size_t start, bool entities, bool attribute) {
    size_t first = text.size();
    text.append(value);
    size_t r = start;
    bool ok = start <= raw.size();
    for (size_t i = 0; ok && i < value.size();) {
      if (r >= raw.size()) {
        ok = false;
        break;
      }
      size_t decoded = 0, len = entities && raw[r] == '&' ? entity_at(raw, r, &decoded) : 0;
      if (len != 0) {
        for (size_t k = 0; k < decoded && i < value.size(); ++k, ++i) pos.push_back(static_cast<uint32_t>(r));
        r += len;
      } else if (raw[r] == value[i]) {
        pos.push_back(static_cast<uint32_t>(r++));
        ++i;
      } else if ((value[i] == '\n' || (attribute && value[i] == ' ')) && raw[r] == '\r') {
        pos.push_back(static_cast<uint32_t>(r));
        r += r + 1 < raw.size() && raw[r + 1] == '\n' ? 2 : 1;
        ++i;
      } else if (attribute && value[i] == ' ' && (raw[r] == '\n' || raw[r] == '\t')) {
        pos.push_back(static_cast<uint32_t>(r++));
        ++i;
      } else {
        ok = false;
      }
    }
    if (!ok) {
      exact = false;
      pos.resize(first);
      pos.insert(pos.end(), value.size(), static_cast<uint32_t>(std::min(start, raw.size())));
    }
  }
  void append_synthetic(std::string_view value, uint32_t at) {
    text.append(value);
    pos.insert(pos.end(), value.size(), at);
  }
};

// One generated ST unit: text and, per line, its origin.
struct Unit {
  std::string name;
  std::string text;
  std::vector<LineOrigin> origins;
};

class Importer {
 public:
  Importer(const std::string& path, SourceManager& sm, DiagEngine& diags, std::vector<uint32_t>* units)
      : path_(path), sm_(sm), diags_(diags), units_(units) {}

  bool run();

 private:
  // ------------------------------------------------------------ positions and errors
  SourceLoc loc_at(size_t offset) const {
    const auto& starts = sm_.file(file_).line_starts;
    auto it = std::upper_bound(starts.begin(), starts.end(), static_cast<uint32_t>(std::min(offset, raw_.size())));
    size_t line = static_cast<size_t>(it - starts.begin());
    return SourceLoc{file_, static_cast<uint32_t>(line), static_cast<uint32_t>(offset - starts[line - 1] + 1)};
  }
  // An element's position: its '<'.
  size_t offset_of(const pugi::xml_node& n) const {
    ptrdiff_t o = n.offset_debug();
    if (o <= 0) return 0;
    return n.type() == pugi::node_element ? static_cast<size_t>(o - 1) : static_cast<size_t>(o);
  }
  SourceLoc loc(const pugi::xml_node& n) const { return loc_at(offset_of(n)); }
  // A structural error: the unit being generated is dropped, so the parser does not
  // report the hole it would leave a second time.
  void error(const char* code, const pugi::xml_node& n, std::string message) {
    diags_.error(code, loc(n), std::move(message));
    ok_ = false;
    unit_broken_ = true;
  }

  // Where the value of attribute `name` of element n starts in the file (found by reading
  // the start tag); npos when it is not there.
  size_t attr_value_offset(const pugi::xml_node& n, std::string_view name) const {
    size_t r = offset_of(n) + 1;
    auto skip_ws = [&] {
      while (r < raw_.size() && std::isspace(static_cast<unsigned char>(raw_[r]))) ++r;
    };
    while (r < raw_.size() && !std::isspace(static_cast<unsigned char>(raw_[r])) && raw_[r] != '>' && raw_[r] != '/') ++r;
    for (int guard = 0; guard < 10000; ++guard) {
      skip_ws();
      if (r >= raw_.size() || raw_[r] == '>' || raw_[r] == '/') return std::string_view::npos;
      size_t name_start = r;
      while (r < raw_.size() && raw_[r] != '=' && !std::isspace(static_cast<unsigned char>(raw_[r])) && raw_[r] != '>') ++r;
      std::string_view attr = std::string_view(raw_).substr(name_start, r - name_start);
      skip_ws();
      if (r >= raw_.size() || raw_[r] != '=') return std::string_view::npos;
      ++r;
      skip_ws();
      if (r >= raw_.size() || (raw_[r] != '"' && raw_[r] != '\'')) return std::string_view::npos;
      char quote = raw_[r++];
      if (attr == name) return r;
      size_t end = raw_.find(quote, r);
      if (end == std::string_view::npos) return std::string_view::npos;
      r = end + 1;
    }
    return std::string_view::npos;
  }

  // The attribute's value as a copy of the user's text.
  Copy attr_copy(const pugi::xml_node& n, const char* name) const {
    Copy c;
    std::string_view value = n.attribute(name).value();
    size_t at = attr_value_offset(n, name);
    if (at == std::string_view::npos) c.append_synthetic(value, static_cast<uint32_t>(offset_of(n)));
    else c.append(value, raw_, at, true, true);
    return c;
  }

  // Required attribute: its value, or an error at the element.
  bool required(const pugi::xml_node& n, const char* attr, const std::string& what, std::string* out) {
    pugi::xml_attribute a = n.attribute(attr);
    if (!a || std::string_view(a.value()).empty()) {
      error("ST603", n, what + " has no '" + attr + "' attribute");
      return false;
    }
    *out = a.value();
    return true;
  }
  // A required name attribute that must be an IEC identifier.
  bool name_of(const pugi::xml_node& n, const std::string& what, std::string* out, const char* attr = "name") {
    if (!required(n, attr, what, out)) return false;
    if (!is_identifier(*out)) {
      error("ST605", n, what + ": '" + *out + "' is not an IEC identifier");
      return false;
    }
    return true;
  }

  // Text content of an element (PCDATA and CDATA, through nested elements such as
  // <xhtml> or <xhtml:p>; sibling paragraphs are separate lines).
  void gather_text(const pugi::xml_node& n, Copy* out, int depth) {
    if (depth > kMaxDepth) {
      error("ST605", n, "text nested too deep (more than " + std::to_string(kMaxDepth) + " elements)");
      return;
    }
    bool element_before = false;
    for (auto c : n.children()) {
      if (c.type() == pugi::node_pcdata || c.type() == pugi::node_cdata) {
        ptrdiff_t o = c.offset_debug();
        out->append(c.value(), raw_, o < 0 ? raw_.size() : static_cast<size_t>(o), c.type() == pugi::node_pcdata, false);
      } else if (c.type() == pugi::node_element) {
        if (element_before && !out->text.empty() && out->text.back() != '\n')
          out->append_synthetic("\n", static_cast<uint32_t>(offset_of(c)));
        gather_text(c, out, depth + 1);
        element_before = true;
      }
    }
  }

  // ------------------------------------------------------------ generated text
  LineOrigin at(const pugi::xml_node& n) const {
    SourceLoc l = loc(n);
    LineOrigin o;
    o.path = path_;
    o.line = l.line;
    o.col = l.col;
    o.exact_columns = false;
    o.generated = true;
    return o;
  }
  // A synthesized line pointing at element n.
  void line(const std::string& text, const pugi::xml_node& n) {
    unit_.text += text;
    unit_.text += '\n';
    unit_.origins.push_back(at(n));
  }
  // prefix + the copy + suffix, as many lines as the copy has, each mapped to the file.
  void copy(const std::string& prefix, const Copy& c, const std::string& suffix) {
    size_t a = 0;
    for (;;) {
      size_t b = c.text.find('\n', a);
      bool last = b == std::string::npos;
      if (last) b = c.text.size();
      LineOrigin o;
      o.path = path_;
      size_t anchor = a < c.pos.size() ? c.pos[a] : c.pos.empty() ? raw_.size() : c.pos.back();
      SourceLoc l = loc_at(anchor);
      o.line = l.line;
      o.col = l.col;
      o.prefix = a == 0 ? static_cast<uint32_t>(prefix.size()) : 0;
      o.exact_columns = c.exact;
      if (c.exact) {
        bool identity = true;
        std::vector<uint32_t> map;
        for (size_t k = a; k < b && o.exact_columns; ++k) {
          SourceLoc lk = loc_at(c.pos[k]);
          if (lk.line != l.line) o.exact_columns = false;
          map.push_back(lk.col - l.col);
          if (map.back() != k - a) identity = false;
        }
        if (o.exact_columns && !identity) o.col_map = std::move(map);
      }
      unit_.text += (a == 0 ? prefix : std::string{}) + c.text.substr(a, b - a) + (last ? suffix : std::string{});
      unit_.text += '\n';
      unit_.origins.push_back(std::move(o));
      if (last) break;
      a = b + 1;
    }
  }
  void begin_unit(const std::string& name) {
    unit_ = Unit{};
    unit_.name = path_ + "(" + name + ")";
    unit_broken_ = false;
  }
  void end_unit() {
    if (unit_broken_) return;
    uint32_t index = sm_.add_generated(std::move(unit_.name), std::move(unit_.text), std::move(unit_.origins));
    units_->push_back(index);
    unit_ = Unit{};
  }

  // ------------------------------------------------------------ types and values
  static bool is_elementary(std::string_view n) {
    static const char* const kNames[] = {"BOOL", "BYTE",  "WORD", "DWORD", "LWORD", "SINT", "INT",  "DINT", "LINT",
                                         "USINT", "UINT", "UDINT", "ULINT", "REAL", "LREAL", "TIME", "LTIME", "DATE",
                                         "LDATE", "DT",   "LDT",  "TOD",   "LTOD",  "CHAR", "WCHAR", "DATE_AND_TIME",
                                         "TIME_OF_DAY"};
    for (const char* k : kNames)
      if (n == k) return true;
    return false;
  }

  // The type element inside a <type> or <baseType> wrapper.
  void type_in(const pugi::xml_node& wrapper, const std::string& what, int depth) {
    pugi::xml_node t = first_element(wrapper);
    if (!t) {
      error("ST603", wrapper, what + ": <" + std::string(local_name(wrapper)) + "> names no type");
      return;
    }
    type_spec(t, what, depth);
  }

  void type_spec(const pugi::xml_node& t, const std::string& what, int depth) {
    if (depth > kMaxDepth) {
      error("ST605", t, what + ": types nested too deep (more than " + std::to_string(kMaxDepth) + ")");
      return;
    }
    std::string_view k = local_name(t);
    std::string s;
    if (is_elementary(k)) {
      line(std::string(k), t);
    } else if (k == "string" || k == "wstring") {
      std::string kw = k == "string" ? "STRING" : "WSTRING";
      if (t.attribute("length")) copy(kw + "[", attr_copy(t, "length"), "]");
      else line(kw, t);
    } else if (k == "derived") {
      if (!required(t, "name", what + ": <derived>", &s)) return;
      if (!is_identifier(s, true)) return error("ST605", t, what + ": '" + s + "' is not a type name");
      copy("", attr_copy(t, "name"), "");
    } else if (k == "array") {
      auto dims = children(t, "dimension");
      if (dims.empty()) return error("ST603", t, what + ": <array> has no <dimension>");
      line("ARRAY [", t);
      for (size_t i = 0; i < dims.size(); ++i) {
        if (!required(dims[i], "lower", what + ": <dimension>", &s) || !required(dims[i], "upper", what + ": <dimension>", &s))
          return;
        copy("", attr_copy(dims[i], "lower"), " ..");
        copy("", attr_copy(dims[i], "upper"), i + 1 < dims.size() ? "," : "");
      }
      line("] OF", t);
      pugi::xml_node base = child(t, "baseType");
      if (!base) return error("ST603", t, what + ": <array> has no <baseType>");
      type_in(base, what, depth + 1);
    } else if (k == "enum") {
      pugi::xml_node values = child(t, "values");
      auto vs = children(values, "value");
      if (vs.empty()) return error("ST603", t, what + ": <enum> has no <values>");
      line("(", t);
      for (size_t i = 0; i < vs.size(); ++i) {
        if (!name_of(vs[i], what + ": enumeration <value>", &s)) return;
        bool has_value = vs[i].attribute("value");
        copy("", attr_copy(vs[i], "name"), has_value || i + 1 == vs.size() ? "" : ",");
        if (has_value) copy(":= ", attr_copy(vs[i], "value"), i + 1 < vs.size() ? "," : "");
      }
      line(")", t);
      if (pugi::xml_node base = child(t, "baseType")) type_in(base, what, depth + 1);
    } else if (k == "struct") {
      line("STRUCT", t);
      for (auto v : children(t, "variable")) variable(v, what, depth + 1);
      line("END_STRUCT", t);
    } else if (k == "subrangeSigned" || k == "subrangeUnsigned") {
      pugi::xml_node range = child(t, "range");
      pugi::xml_node base = child(t, "baseType");
      if (!range || !base) return error("ST603", t, what + ": <" + std::string(k) + "> needs <range> and <baseType>");
      if (!required(range, "lower", what + ": <range>", &s) || !required(range, "upper", what + ": <range>", &s)) return;
      type_in(base, what, depth + 1);
      copy("(", attr_copy(range, "lower"), " ..");
      copy("", attr_copy(range, "upper"), ")");
    } else if (k == "pointer") {
      pugi::xml_node base = child(t, "baseType");
      if (!base) return error("ST603", t, what + ": <pointer> has no <baseType>");
      line("POINTER TO", t);
      type_in(base, what, depth + 1);
    } else {
      error("ST605", t, what + ": type <" + std::string(k) + "> is not supported");
    }
  }

  // <initialValue>'s content: simpleValue, arrayValue or structValue.
  void value(const pugi::xml_node& v, const std::string& what, int depth, const std::string& suffix) {
    if (depth > kMaxDepth) return error("ST605", v, what + ": values nested too deep (more than " + std::to_string(kMaxDepth) + ")");
    std::string_view k = local_name(v);
    std::string s;
    if (k == "simpleValue") {
      if (!required(v, "value", what + ": <simpleValue>", &s)) return;
      Copy c = attr_copy(v, "value");
      // CODESYS writes an enumeration value E.V; plcfi reads E#V (same columns).
      size_t dot = c.text.find('.');
      if (dot != std::string::npos && is_identifier(c.text, true) && c.text.find('.', dot + 1) == std::string::npos &&
          enums_.count(canon(std::string_view(c.text).substr(0, dot))))
        c.text[dot] = '#';
      copy("", c, suffix);
    } else if (k == "arrayValue") {
      auto items = children(v, "value");
      line("[", v);
      for (size_t i = 0; i < items.size(); ++i) {
        std::string sep = i + 1 < items.size() ? "," : "";
        pugi::xml_node inner = first_element(items[i]);
        if (!inner) return error("ST603", items[i], what + ": array <value> is empty");
        bool repeated = items[i].attribute("repetitionValue");
        if (repeated) {
          std::string rep = items[i].attribute("repetitionValue").value();
          if (rep.empty() || rep.size() > 9 || !std::all_of(rep.begin(), rep.end(), [](char c) { return c >= '0' && c <= '9'; }))
            return error("ST605", items[i], what + ": repetitionValue '" + rep + "' is not a whole number");
          copy("", attr_copy(items[i], "repetitionValue"), "(");
          value(inner, what, depth + 1, ")" + sep);
        } else {
          value(inner, what, depth + 1, sep);
        }
      }
      line("]" + suffix, v);
    } else if (k == "structValue") {
      auto items = children(v, "value");
      if (items.empty()) return error("ST603", v, what + ": <structValue> has no <value>");
      line("(", v);
      for (size_t i = 0; i < items.size(); ++i) {
        if (!name_of(items[i], what + ": struct <value>", &s, "member")) return;
        pugi::xml_node inner = first_element(items[i]);
        if (!inner) return error("ST603", items[i], what + ": struct <value> is empty");
        copy("", attr_copy(items[i], "member"), " :=");
        value(inner, what, depth + 1, i + 1 < items.size() ? "," : "");
      }
      line(")" + suffix, v);
    } else {
      error("ST605", v, what + ": initial value <" + std::string(k) + "> is not supported");
    }
  }

  // <variable name=.. [address=..]><type/><initialValue/></variable> -> one declaration.
  void variable(const pugi::xml_node& v, const std::string& what, int depth) {
    std::string name;
    if (!name_of(v, what + ": <variable>", &name)) return;
    std::string var_what = what + ", variable '" + name + "'";
    pugi::xml_node type = child(v, "type");
    if (!type) return error("ST603", v, var_what + " has no <type>");
    copy("", attr_copy(v, "name"), "");
    if (v.attribute("address") && *v.attribute("address").value()) copy("AT ", attr_copy(v, "address"), "");
    line(":", v);
    type_in(type, var_what, depth + 1);
    if (pugi::xml_node init = child(v, "initialValue")) {
      pugi::xml_node val = first_element(init);
      if (!val) return error("ST603", init, var_what + ": <initialValue> is empty");
      line(":=", init);
      value(val, var_what, depth + 1, ";");
    } else {
      line(";", v);
    }
  }

  // A <data name=".../NAME"> under the node's <addData>.
  static pugi::xml_node add_data(const pugi::xml_node& n, std::string_view name) {
    for (auto data : children(child(n, "addData"), "data")) {
      std::string_view full = data.attribute("name").value();
      if (full.size() >= name.size() && full.substr(full.size() - name.size()) == name &&
          (full.size() == name.size() || full[full.size() - name.size() - 1] == '/'))
        return data;
    }
    return {};
  }
  // The CODESYS plain-text declaration of a POU, method, property or variable list.
  pugi::xml_node plain_text(const pugi::xml_node& n) {
    pugi::xml_node d = add_data(n, kPlainText);
    if (!d) d = add_data(child(n, "interface"), kPlainText);
    return d ? child(d, "InterfaceAsPlainText") : pugi::xml_node{};
  }
  bool copy_plain_text(const pugi::xml_node& text) {
    Copy c;
    gather_text(text, &c, 0);
    while (!c.text.empty() && (c.text.back() == '\n' || c.text.back() == ' ' || c.text.back() == '\t' || c.text.back() == '\r')) {
      c.text.pop_back();
      c.pos.pop_back();
    }
    if (c.text.empty()) return false;
    copy("", c, "");
    return true;
  }

  // The VAR blocks of an <interface>.
  void var_blocks(const pugi::xml_node& iface, const std::string& what) {
    static const std::pair<const char*, const char*> kBlocks[] = {
        {"inputVars", "VAR_INPUT"},   {"outputVars", "VAR_OUTPUT"}, {"inOutVars", "VAR_IN_OUT"},
        {"localVars", "VAR"},         {"tempVars", "VAR_TEMP"},     {"externalVars", "VAR_EXTERNAL"},
        {"globalVars", "VAR_GLOBAL"}, {"accessVars", nullptr}};
    for (auto block : iface.children()) {
      if (block.type() != pugi::node_element) continue;
      std::string_view k = local_name(block);
      for (const auto& [element, keyword] : kBlocks) {
        if (k != element) continue;
        if (!keyword) {
          error("ST605", block, what + ": <accessVars> are not supported");
          break;
        }
        var_block(block, keyword, what);
      }
    }
  }
  void var_block(const pugi::xml_node& block, const std::string& keyword, const std::string& what) {
    std::string head = keyword;
    if (attr_true(block, "constant")) head += " CONSTANT";
    if (attr_true(block, "retain")) head += " RETAIN";
    if (attr_true(block, "nonretain")) head += " NON_RETAIN";
    if (attr_true(block, "persistent")) head += " PERSISTENT";
    line(head, block);
    for (auto v : children(block, "variable")) variable(v, what, 0);
    line("END_VAR", block);
  }

  // ------------------------------------------------------------ POUs
  // Emits the ST body of `owner` (a pou, method, action, accessor); false after an error.
  bool body(const pugi::xml_node& owner, const std::string& what) {
    pugi::xml_node b = child(owner, "body");
    if (!b) return true;
    // ST and IL bodies are text the front end reads (it tells IL by its first line), each
    // line located at its place in the XML.
    for (const char* lang : {"ST", "IL"})
      if (pugi::xml_node text = child(b, lang)) {
        Copy c;
        gather_text(text, &c, 0);
        if (!c.text.empty()) copy("", c, "");
        return true;
      }
    for (const char* lang : {"LD", "FBD", "SFC"})
      if (child(b, lang)) {
        // The POU stays, with an empty body: its interface is sound, so its users compile.
        diags_.error("ST604", loc(b), what + " has an " + std::string(lang) + " body: plcfi reads LD, FBD and SFC bodies "
                                      "of POUs, not of methods, actions or property accessors (write this one in ST or IL)");
        ok_ = false;
        return false;
      }
    if (pugi::xml_node other = first_element(b); other && !is(other, "addData") && !is(other, "documentation")) {
      diags_.error("ST604", loc(b), what + " has a body in <" + std::string(local_name(other)) +
                                        ">: plcfi reads ST, IL, LD, FBD and SFC bodies");
      ok_ = false;
      return false;
    }
    return true;
  }

  // "METHOD M : T" from structured elements (no plain text).
  void header(const std::string& keyword, const pugi::xml_node& n, const pugi::xml_node& iface, const std::string& suffix = "") {
    copy(keyword + " ", attr_copy(n, "name"), suffix);
    if (pugi::xml_node ret = child(iface, "returnType")) {
      line(":", ret);
      type_in(ret, keyword + " '" + std::string(n.attribute("name").value()) + "'", 0);
    }
  }

  void method(const pugi::xml_node& m, const std::string& owner) {
    std::string name;
    if (!name_of(m, owner + ": <Method>", &name)) return;
    std::string what = "method '" + name + "' of " + owner;
    pugi::xml_node iface = child(m, "interface");
    pugi::xml_node text = plain_text(m);
    if (!text || !copy_plain_text(text)) {
      header("METHOD", m, iface);
      var_blocks(iface, what);
    }
    body(m, what);
    line("END_METHOD", m);
  }

  // An action becomes a METHOD without variables: it runs on the POU's own variables and
  // is called the same way (inst.A(), or A() inside).
  void action(const pugi::xml_node& a, const std::string& owner) {
    std::string name;
    if (!name_of(a, owner + ": <action>", &name)) return;
    copy("METHOD ", attr_copy(a, "name"), "");
    body(a, "action '" + name + "' of " + owner);
    line("END_METHOD", a);
  }

  void property(const pugi::xml_node& p, const std::string& owner) {
    std::string name;
    if (!name_of(p, owner + ": <Property>", &name)) return;
    std::string what = "property '" + name + "' of " + owner;
    pugi::xml_node iface = child(p, "interface");
    pugi::xml_node text = plain_text(p);
    if (!text || !copy_plain_text(text)) {
      if (!child(iface, "returnType")) return error("ST603", p, what + " has no <returnType>");
      header("PROPERTY", p, iface);
    }
    for (const auto& [element, keyword] : {std::pair{"GetAccessor", "GET"}, std::pair{"SetAccessor", "SET"}}) {
      pugi::xml_node acc = child(p, element);
      if (!acc) continue;
      line(keyword, acc);
      pugi::xml_node acc_text = plain_text(acc);
      std::string acc_what = std::string(keyword == std::string("GET") ? "getter" : "setter") + " of " + what;
      if (acc_text) {
        Copy c;
        gather_text(acc_text, &c, 0);
        // CODESYS may write the accessor's own header; the generated GET/SET is then enough.
        size_t skip = 0;
        while (skip < c.text.size() && std::isspace(static_cast<unsigned char>(c.text[skip]))) ++skip;
        std::string head = canon(std::string_view(c.text).substr(skip, 3));
        if (head == keyword && (skip + 3 >= c.text.size() || !std::isalnum(static_cast<unsigned char>(c.text[skip + 3])))) {
          size_t nl = c.text.find('\n', skip);
          c.text.erase(0, nl == std::string::npos ? c.text.size() : nl + 1);
          c.pos.erase(c.pos.begin(), c.pos.begin() + static_cast<ptrdiff_t>(std::min(c.pos.size(), nl == std::string::npos ? c.pos.size() : nl + 1)));
        }
        if (!c.text.empty()) copy("", c, "");
      } else {
        var_blocks(child(acc, "interface"), acc_what);
      }
      body(acc, acc_what);
      line("END_" + std::string(keyword), acc);
    }
    line("END_PROPERTY", p);
  }

  void pou(const pugi::xml_node& p) {
    std::string name, type;
    if (!name_of(p, "<pou>", &name)) return;
    std::string what = "POU '" + name + "'";
    if (!required(p, "pouType", what, &type)) return;
    std::string keyword;
    if (type == "program") keyword = "PROGRAM";
    else if (type == "functionBlock") keyword = "FUNCTION_BLOCK";
    else if (type == "function") keyword = "FUNCTION";
    else return error("ST605", p, what + ": pouType '" + type + "' is not program, functionBlock or function");

    begin_unit(name);
    pugi::xml_node iface = child(p, "interface");
    pugi::xml_node text = plain_text(p);
    if (!text || !copy_plain_text(text)) {
      std::string extends;
      if (pugi::xml_node inh = add_data(p, "pouinheritance")) {
        pugi::xml_node ext = child(child(inh, "Inheritance"), "Extends");
        std::string base = ext.text().get();
        if (ext && !is_identifier(base, true)) return error("ST605", ext, what + ": '" + base + "' is not a type name");
        if (ext) extends = " EXTENDS " + base;
      }
      header(keyword, p, iface, extends);
      var_blocks(iface, what);
    }
    // A Ladder Diagram or Function Block Diagram body becomes ST (import/ld.hpp); its
    // variables come first.
    LdTranslation ld;
    pugi::xml_node ld_body = child(child(p, "body"), "LD");
    if (!ld_body) ld_body = child(child(p, "body"), "FBD");
    if (ld_body) {
      LdError err;
      if (!ld_to_st(ld_body, what, keyword != "FUNCTION", &ld, &err)) return error(err.code.c_str(), err.at, err.message);
      for (const auto& v : ld.vars) line(v.text, v.at);
    }
    // An SFC body becomes textual SFC (import/sfc.hpp); the POU's <actions> and
    // <transitions> are the chart's and go into it. Its conditions drawn in LD or FBD
    // bring variables, which come first.
    pugi::xml_node sfc_body = child(child(p, "body"), "SFC");
    std::vector<SfcPiece> chart;
    if (sfc_body && !ld_body) {
      std::vector<SfcPiece> chart_vars;
      SfcError err;
      if (!sfc_to_text(sfc_body, p, what, &chart, &chart_vars, &err)) return error(err.code.c_str(), err.at, err.message);
      for (const SfcPiece& v : chart_vars) line(v.text, v.at);
    }
    for (auto data : children(child(p, "addData"), "data")) {
      std::string_view dn = data.attribute("name").value();
      for (auto item : data.children()) {
        if (item.type() != pugi::node_element) continue;
        if (dn.ends_with("/method") && is(item, "Method")) method(item, what);
        else if (dn.ends_with("/property") && is(item, "Property")) property(item, what);
        else if (dn.ends_with("/action") && (is(item, "Action") || is(item, "action"))) action(item, what);
      }
    }
    if (!sfc_body)
      for (auto a : children(child(p, "actions"), "action")) action(a, what);
    if (ld_body) {
      for (const auto& st : ld.body) line(st.text, st.at);
    } else if (sfc_body) {
      for (const SfcPiece& piece : chart) {
        if (!piece.copy) {
          line(piece.text, piece.at);
          continue;
        }
        Copy c;
        gather_text(piece.copy, &c, 0);
        copy(piece.text, c, piece.suffix);
      }
    } else {
      body(p, what);
    }
    line("END_" + keyword, p);
    end_unit();
  }

  void data_type(const pugi::xml_node& d) {
    std::string name;
    if (!name_of(d, "<dataType>", &name)) return;
    std::string what = "data type '" + name + "'";
    // CODESYS writes the declaration as the user typed it too (TYPE ... END_TYPE): preferred.
    if (pugi::xml_node text = plain_text(d)) {
      begin_unit(name);
      if (copy_plain_text(text)) return end_unit();
    }
    pugi::xml_node base = child(d, "baseType");
    if (!base) return error("ST603", d, what + " has no <baseType>");
    begin_unit(name);
    line("TYPE", d);
    copy("", attr_copy(d, "name"), " :");
    type_in(base, what, 0);
    if (pugi::xml_node init = child(d, "initialValue")) {
      if (pugi::xml_node val = first_element(init)) {
        line(":=", init);
        value(val, what, 0, ";");
      } else {
        line(";", d);
      }
    } else {
      line(";", d);
    }
    line("END_TYPE", d);
    end_unit();
  }

  // <globalVars> (with its plain text, if any) as a VAR_GLOBAL block.
  void global_vars(const pugi::xml_node& g, const std::string& what) {
    pugi::xml_node text = plain_text(g);
    if (text && copy_plain_text(text)) return;
    var_block(g, "VAR_GLOBAL", what);
  }

  void configuration(const pugi::xml_node& cfg) {
    std::string name, s;
    if (!name_of(cfg, "<configuration>", &name)) return;
    std::string what = "configuration '" + name + "'";
    begin_unit(name);
    copy("CONFIGURATION ", attr_copy(cfg, "name"), "");
    for (auto g : children(cfg, "globalVars")) global_vars(g, what);
    for (auto res : children(cfg, "resource")) {
      std::string rname;
      if (!name_of(res, what + ": <resource>", &rname)) continue;
      std::string rwhat = "resource '" + rname + "'";
      copy("RESOURCE ", attr_copy(res, "name"), " ON PLC");
      for (auto g : children(res, "globalVars")) global_vars(g, rwhat);
      for (auto task : children(res, "task")) {
        std::string tname;
        if (!name_of(task, rwhat + ": <task>", &tname)) continue;
        std::string twhat = "task '" + tname + "'";
        copy("TASK ", attr_copy(task, "name"), " (");
        bool first = true;
        if (pugi::xml_attribute iv = task.attribute("interval")) {
          std::string text = iv.value();
          std::string lit = iso_to_time_literal(text);
          std::string upper = canon(text);
          if (lit.empty() && (upper.starts_with("T#") || upper.starts_with("TIME#") || upper.starts_with("LT#") ||
                              upper.starts_with("LTIME#"))) {
            copy("INTERVAL := ", attr_copy(task, "interval"), "");
          } else if (!lit.empty()) {
            line("INTERVAL := " + lit, task);
          } else {
            error("ST605", task, twhat + ": interval '" + text + "' is not a duration (PT0.01S or T#10ms)");
          }
          first = false;
        }
        if (task.attribute("priority")) {
          copy(first ? "PRIORITY := " : ", PRIORITY := ", attr_copy(task, "priority"), "");
          first = false;
        }
        if (task.attribute("single") && *task.attribute("single").value()) {
          copy(first ? "SINGLE := " : ", SINGLE := ", attr_copy(task, "single"), "");
        }
        line(");", task);
        for (auto inst : children(task, "pouInstance")) pou_instance(inst, &tname);
      }
      for (auto inst : children(res, "pouInstance")) pou_instance(inst, nullptr);
      line("END_RESOURCE", res);
    }
    line("END_CONFIGURATION", cfg);
    end_unit();
  }

  void pou_instance(const pugi::xml_node& inst, const std::string* task) {
    std::string name, type;
    if (!name_of(inst, "<pouInstance>", &name)) return;
    if (!name_of(inst, "pouInstance '" + name + "'", &type, "typeName")) return;
    copy("PROGRAM ", attr_copy(inst, "name"), task ? " WITH " + *task : "");
    copy(": ", attr_copy(inst, "typeName"), ";");
  }

  const std::string& path_;
  SourceManager& sm_;
  DiagEngine& diags_;
  std::vector<uint32_t>* units_;
  uint32_t file_ = 0;
  std::string_view raw_;
  Unit unit_;
  std::set<std::string> enums_;  // canonical names of the enumeration data types
  bool unit_broken_ = false;
  bool ok_ = true;
};

bool Importer::run() {
  // The file may be loaded already (the engine reads it first, to report an unreadable
  // file like any other); generated units are never the file itself.
  bool found = false;
  for (uint32_t f = 0; f < sm_.size() && !found; ++f)
    if (sm_.file(f).path == path_ && sm_.file(f).origins.empty()) file_ = f, found = true;
  if (!found) {
    std::string err;
    if (!sm_.load(path_, &file_, &err)) {
      // A placeholder so the message names the file; its text is empty.
      file_ = sm_.add(path_, "");
      std::string reason = err.starts_with(path_ + ": ") ? err.substr(path_.size() + 2) : err;
      diags_.error("ST601", SourceLoc{file_, 0, 0}, reason);
      return false;
    }
  }
  raw_ = sm_.file(file_).text;
  if (raw_.size() >= 2 && ((raw_[0] == '\xFF' && raw_[1] == '\xFE') || (raw_[0] == '\xFE' && raw_[1] == '\xFF'))) {
    diags_.error("ST601", SourceLoc{file_, 1, 1}, "the file is UTF-16: plcfi reads PLCopen XML in UTF-8 (save it as UTF-8)");
    return false;
  }
  // pugixml skips a UTF-8 byte order mark; offsets stay those of the buffer given.
  pugi::xml_document doc;
  pugi::xml_parse_result res =
      doc.load_buffer(raw_.data(), raw_.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!res) {
    size_t off = res.offset < 0 ? 0 : static_cast<size_t>(res.offset);
    diags_.error("ST601", loc_at(off), std::string("not well-formed XML: ") + res.description());
    return false;
  }
  pugi::xml_node project = doc.document_element();
  if (!is(project, "project")) {
    diags_.error("ST602", project ? loc(project) : SourceLoc{file_, 1, 1},
                 "not a PLCopen XML project: the root element is " +
                     (project ? "<" + std::string(project.name()) + ">" : std::string("missing")) + ", expected <project>");
    return false;
  }
  pugi::xml_node types = child(project, "types");
  for (auto d : children(child(types, "dataTypes"), "dataType"))
    if (child(child(d, "baseType"), "enum")) enums_.insert(canon(d.attribute("name").value()));
  for (auto d : children(child(types, "dataTypes"), "dataType")) data_type(d);
  for (auto p : children(child(types, "pous"), "pou")) pou(p);
  // CODESYS global variable lists: <addData><data name=".../globalvars"><globalVars name=..>.
  for (auto data : children(child(project, "addData"), "data")) {
    if (!std::string_view(data.attribute("name").value()).ends_with("/globalvars")) continue;
    for (auto g : children(data, "globalVars")) {
      begin_unit(g.attribute("name").value());
      global_vars(g, "global variable list '" + std::string(g.attribute("name").value()) + "'");
      end_unit();
    }
  }
  for (auto cfg : children(child(child(project, "instances"), "configurations"), "configuration")) configuration(cfg);
  return ok_;
}

}  // namespace

bool import_plcopen(const std::string& path, SourceManager& sm, DiagEngine& diags, std::vector<uint32_t>* units) {
  return Importer(path, sm, diags, units).run();
}

}  // namespace plcfi::st
