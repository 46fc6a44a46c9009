// TwinCAT 3 PLC projects: a .plcproj and the object files it lists (.TcPOU, .TcDUT, .TcGVL,
// .TcIO, .TcTTO) become ST units of the one front end. Each object file's declaration and
// implementation texts (CDATA) are copied line for line into the unit, so every copied line
// maps 1:1 back to its line and column in the XML file; the keywords the XML leaves implicit
// (END_METHOD, GET, END_FUNCTION_BLOCK, the CONFIGURATION built from the tasks) point at the
// element they stand for.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <pugixml.hpp>

#include "import/import.hpp"

namespace plcfi::st {

namespace {

namespace fs = std::filesystem;

// Codes of this reader (driver/st/DIAGNOSTICS.md, "Import errors").
constexpr const char* kNotWellFormed = "ST620";  // not well-formed XML
constexpr const char* kNotTwinCat = "ST621";     // not a TwinCAT object or project, or an object missing a part
constexpr const char* kMissingFile = "ST622";    // a Compile item names a file that cannot be read
constexpr const char* kNotSt = "ST623";          // a body in LD, FBD, SFC, CFC, ...
constexpr const char* kBadTask = "ST624";        // a task that cannot be scheduled as written

// One generated ST unit: text and, per line, where it came from.
class Unit {
 public:
  // Copies user text that starts at (line, col) of `path`; its lines map 1:1. `exact`:
  // the text is verbatim (CDATA), so columns map too.
  void copy(std::string_view text, const std::string& path, uint32_t line, uint32_t col, bool exact) {
    size_t i = 0;
    while (i < text.size()) {
      size_t nl = text.find('\n', i);
      size_t end = nl == std::string_view::npos ? text.size() : nl + 1;
      LineOrigin o;
      o.path = path;
      o.line = line;
      o.col = i == 0 ? col : 1;
      o.exact_columns = exact;
      text_.append(text.substr(i, end - i));
      origins_.push_back(std::move(o));
      ++line;
      i = end;
    }
    if (!text.empty() && text.back() != '\n') text_ += '\n';
  }
  // A line the XML leaves implicit (END_METHOD, GET, ...): it points at `loc` in `path`.
  void synth(std::string line_text, const std::string& path, SourceLoc loc) {
    LineOrigin o;
    o.path = path;
    o.line = loc.line;
    o.col = loc.col;
    o.exact_columns = false;
    text_ += line_text + "\n";
    origins_.push_back(std::move(o));
  }
  bool empty() const { return text_.empty(); }
  std::string take_text() { return std::move(text_); }
  std::vector<LineOrigin> take_origins() { return std::move(origins_); }

 private:
  std::string text_;
  std::vector<LineOrigin> origins_;
};

struct TaskCall {
  std::string program;
  SourceLoc loc;  // the <Name> element
  std::string path;
};

struct Task {
  std::string name;
  std::string path;  // the .TcTTO file
  SourceLoc loc;     // the <Task> element
  uint64_t cycle_us = 0;
  int64_t priority = 0;
  std::vector<TaskCall> calls;
};

// A file of the import: loaded into the source manager, parsed.
struct XmlFile {
  std::string path;
  uint32_t index = 0;
  pugi::xml_document doc;
};

class Importer {
 public:
  Importer(SourceManager& sm, DiagEngine& diags, std::vector<uint32_t>* units, std::vector<LibraryParam>* params)
      : sm_(sm), diags_(diags), units_(units), params_(params) {}

  void run(const std::string& path);

 private:
  bool load(const std::string& path, XmlFile* f, const SourceLoc* where_listed, const std::string* listed_as);
  SourceLoc loc_of(const XmlFile& f, ptrdiff_t offset) const;
  SourceLoc loc_of(const XmlFile& f, const pugi::xml_node& n) const;
  void read_project(XmlFile& f);
  void read_object(const std::string& path, SourceLoc where_listed, const std::string& listed_as);
  void read_pou(const XmlFile& f, const pugi::xml_node& pou);
  void read_itf(const XmlFile& f, const pugi::xml_node& itf);
  void read_declaration_only(const XmlFile& f, const pugi::xml_node& obj, const char* what);
  void read_task(const XmlFile& f, const pugi::xml_node& task);
  bool copy_declaration(const XmlFile& f, const pugi::xml_node& owner, const std::string& what, Unit& u, bool required);
  void copy_body(const XmlFile& f, const pugi::xml_node& owner, const std::string& what, Unit& u);
  void copy_text(const XmlFile& f, const pugi::xml_node& holder, Unit& u);
  void read_members(const XmlFile& f, const pugi::xml_node& owner, const std::string& owner_what, bool prototypes,
                    Unit& u);
  void read_property(const XmlFile& f, const pugi::xml_node& prop, bool prototype, Unit& u);
  void add_unit(const std::string& file_path, const std::string& object, Unit& u);
  void add_configuration(const std::string& path, SourceLoc loc, const std::string& name);

  SourceManager& sm_;
  DiagEngine& diags_;
  std::vector<uint32_t>* units_;
  std::vector<LibraryParam>* params_;
  std::vector<Task> tasks_;
  std::set<std::string> seen_;  // object files already read (a project listing one twice)
};

std::string ext_of(std::string_view path) {
  size_t slash = path.find_last_of("/\\");
  std::string_view name = slash == std::string_view::npos ? path : path.substr(slash + 1);
  size_t dot = name.rfind('.');
  return dot == std::string_view::npos ? std::string() : canon(name.substr(dot + 1));
}

// A name usable as an ST identifier and a file stem (the GVL's scope is its unit's stem).
std::string identifier(std::string_view name, std::string_view fallback) {
  std::string out;
  for (char c : name.empty() ? fallback : name) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out.insert(out.begin(), '_');
  return out;
}

bool is_identifier(std::string_view s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

// The first keyword of a declaration, past blanks, comments and pragmas, in upper case.
std::string first_keyword(std::string_view t) {
  size_t i = 0;
  while (i < t.size()) {
    char c = t[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else if (t.compare(i, 2, "//") == 0) {
      size_t nl = t.find('\n', i);
      i = nl == std::string_view::npos ? t.size() : nl + 1;
    } else if (t.compare(i, 2, "(*") == 0 || t.compare(i, 2, "/*") == 0) {
      size_t e = t.find(t[i] == '(' ? "*)" : "*/", i + 2);
      i = e == std::string_view::npos ? t.size() : e + 2;
    } else if (c == '{') {
      size_t e = t.find('}', i);
      i = e == std::string_view::npos ? t.size() : e + 1;
    } else {
      break;
    }
  }
  size_t j = i;
  while (j < t.size() && (std::isalnum(static_cast<unsigned char>(t[j])) || t[j] == '_')) ++j;
  return canon(t.substr(i, j - i));
}

// `rel` (a Compile item: backslashes, relative to the project) below `dir`, each part
// matched ignoring case when the exact name is not there (projects come from Windows).
// Empty when some part matches nothing.
std::string find_ignoring_case(const fs::path& dir, std::string rel) {
  std::replace(rel.begin(), rel.end(), '\\', '/');
  fs::path cur = dir;
  size_t i = 0;
  while (i <= rel.size()) {
    size_t slash = rel.find('/', i);
    if (slash == std::string::npos) slash = rel.size();
    std::string part = rel.substr(i, slash - i);
    i = slash + 1;
    if (part.empty() || part == ".") continue;
    std::error_code ec;
    fs::path exact = cur / part;
    if (part == ".." || fs::exists(exact, ec)) {
      cur = exact;
      continue;
    }
    bool found = false;
    for (fs::directory_iterator it(cur, ec), end; !ec && it != end; it.increment(ec)) {
      if (iequals(it->path().filename().string(), part)) {
        cur = it->path();
        found = true;
        break;
      }
    }
    if (!found) return {};
  }
  return cur.string();
}

void Importer::run(const std::string& path) {
  if (ext_of(path) == "PLCPROJ") {
    XmlFile f;
    if (load(path, &f, nullptr, nullptr)) read_project(f);
  } else {
    read_object(path, SourceLoc{}, {});
  }
}

// Loads `path` into the source manager (once: a file given twice is the same buffer) and
// parses it. A file that cannot be read is reported where it was listed.
bool Importer::load(const std::string& path, XmlFile* f, const SourceLoc* where_listed, const std::string* listed_as) {
  f->path = path;
  bool found = false;
  for (uint32_t i = 0; i < sm_.size() && !found; ++i)
    if (sm_.file(i).path == path && sm_.file(i).origins.empty()) f->index = i, found = true;
  std::string err;
  if (!found && !sm_.load(path, &f->index, &err)) {
    if (where_listed && where_listed->valid())
      diags_.error(kMissingFile, *where_listed, "Compile item '" + *listed_as + "': " + err);
    else  // the file named on the command line: an empty buffer gives the message its name
      diags_.error(kMissingFile, SourceLoc{sm_.add(path, ""), 0, 0}, err);
    return false;
  }
  const std::string& text = sm_.file(f->index).text;
  // Verbatim text (no end-of-line normalisation): offsets and CDATA lines match the file.
  // The bytes are read as UTF-8 (TwinCAT writes UTF-8 with a byte-order mark).
  pugi::xml_parse_result r = f->doc.load_buffer(text.data(), text.size(), pugi::parse_default & ~pugi::parse_eol,
                                                pugi::encoding_utf8);
  if (!r) {
    diags_.error(kNotWellFormed, loc_of(*f, r.offset), std::string("not well-formed XML: ") + r.description());
    return false;
  }
  return true;
}

SourceLoc Importer::loc_of(const XmlFile& f, ptrdiff_t offset) const {
  const SourceFile& sf = sm_.file(f.index);
  if (offset < 0) return SourceLoc{f.index, 1, 1};
  size_t off = std::min(static_cast<size_t>(offset), sf.text.size());
  auto it = std::upper_bound(sf.line_starts.begin(), sf.line_starts.end(), static_cast<uint32_t>(off));
  uint32_t line = static_cast<uint32_t>(it - sf.line_starts.begin());
  return SourceLoc{f.index, line, static_cast<uint32_t>(off - sf.line_starts[line - 1] + 1)};
}

// An element's position is that of its '<'.
SourceLoc Importer::loc_of(const XmlFile& f, const pugi::xml_node& n) const {
  ptrdiff_t off = n.offset_debug();
  if (off > 0 && n.type() == pugi::node_element) --off;
  return loc_of(f, off);
}

// <Project> <ItemGroup> <Compile Include="POUs\MAIN.TcPOU"/> ...: every listed object
// file, and the parameters the project sets on its library references; other items
// (folders, the references themselves) are not ours to read.
void Importer::read_project(XmlFile& f) {
  pugi::xml_node project = f.doc.document_element();
  if (std::string_view(project.name()) != "Project") {
    diags_.error(kNotTwinCat, loc_of(f, project),
                 std::string("not a TwinCAT PLC project: the root element is <") + project.name() +
                     ">, expected <Project>");
    return;
  }
  const fs::path dir = fs::path(f.path).parent_path();
  for (pugi::xml_node group : project.children("ItemGroup")) {
    for (pugi::xml_node ref : group.children())
      for (pugi::xml_node param : ref.child("Parameters").children("Parameter"))
        if (params_)
          params_->push_back(LibraryParam{param.attribute("ListName").value(), param.child_value("Key"),
                                          param.child_value("Value"), loc_of(f, param)});
    for (pugi::xml_node item : group.children("Compile")) {
      std::string include = item.attribute("Include").value();
      SourceLoc where = loc_of(f, item);
      const std::string ext = ext_of(include);
      if (ext != "TCPOU" && ext != "TCDUT" && ext != "TCGVL" && ext != "TCIO" && ext != "TCTTO") continue;
      std::string found = find_ignoring_case(dir.empty() ? fs::path(".") : dir, include);
      if (found.empty()) {
        std::string rel = include;
        std::replace(rel.begin(), rel.end(), '\\', '/');
        diags_.error(kMissingFile, where, "Compile item '" + include + "': no file " + (dir / rel).string() +
                                              " (not even ignoring case)");
        continue;
      }
      read_object(found, where, include);
    }
  }
  if (!tasks_.empty()) {
    std::string name = project.child("PropertyGroup").child_value("Name");
    add_configuration(f.path, loc_of(f, project), identifier(name, fs::path(f.path).stem().string()));
  }
}

// <TcPlcObject> holding one POU, DUT, GVL, Itf or Task.
void Importer::read_object(const std::string& path, SourceLoc where_listed, const std::string& listed_as) {
  std::error_code ec;
  fs::path key = fs::weakly_canonical(path, ec);
  if (!seen_.insert(ec ? path : key.string()).second) return;
  XmlFile f;
  if (!load(path, &f, &where_listed, &listed_as)) return;
  pugi::xml_node root = f.doc.document_element();
  if (std::string_view(root.name()) != "TcPlcObject") {
    diags_.error(kNotTwinCat, loc_of(f, root),
                 std::string("not a TwinCAT PLC object: the root element is <") + root.name() +
                     ">, expected <TcPlcObject>");
    return;
  }
  const size_t tasks_before = tasks_.size();
  bool any = false;
  for (pugi::xml_node obj : root.children()) {
    if (obj.type() != pugi::node_element) continue;
    std::string_view kind = obj.name();
    if (kind == "POU") read_pou(f, obj);
    else if (kind == "Itf") read_itf(f, obj);
    else if (kind == "DUT") read_declaration_only(f, obj, "DUT");
    else if (kind == "GVL") read_declaration_only(f, obj, "GVL");
    else if (kind == "Task") read_task(f, obj);
    else continue;
    any = true;
  }
  if (!any) {
    diags_.error(kNotTwinCat, loc_of(f, root), "TcPlcObject holds no POU, DUT, GVL, Itf or Task element");
    return;
  }
  // A task file given on its own: its tasks are the configuration.
  if (!where_listed.valid() && tasks_.size() > tasks_before)
    add_configuration(path, loc_of(f, root), identifier(fs::path(path).stem().string(), "Tasks") + "_Config");
}

// Copies the text of <Declaration>, or of <ST> (CDATA, or escaped text) into `u`.
void Importer::copy_text(const XmlFile& f, const pugi::xml_node& holder, Unit& u) {
  for (pugi::xml_node t : holder.children()) {
    if (t.type() != pugi::node_cdata && t.type() != pugi::node_pcdata) continue;
    SourceLoc at = loc_of(f, t.offset_debug());
    // Escaped text (&lt;) is shorter than in the file: lines still map, columns not.
    u.copy(t.value(), f.path, at.line, at.col, t.type() == pugi::node_cdata);
  }
}

bool Importer::copy_declaration(const XmlFile& f, const pugi::xml_node& owner, const std::string& what, Unit& u,
                                bool required) {
  pugi::xml_node decl = owner.child("Declaration");
  if (!decl) {
    if (required) diags_.error(kNotTwinCat, loc_of(f, owner), what + " has no <Declaration>");
    return false;
  }
  copy_text(f, decl, u);
  return true;
}

// <Implementation><ST>...</ST></Implementation>; any other language is an error naming it.
void Importer::copy_body(const XmlFile& f, const pugi::xml_node& owner, const std::string& what, Unit& u) {
  pugi::xml_node impl = owner.child("Implementation");
  if (!impl) return;
  for (pugi::xml_node lang : impl.children()) {
    if (lang.type() != pugi::node_element) continue;
    if (std::string_view(lang.name()) == "ST") {
      copy_text(f, lang, u);
    } else {
      diags_.error(kNotSt, loc_of(f, lang), what + " is written in " + lang.name() +
                                                ": plcfi reads Structured Text (ST) bodies only");
    }
  }
}

// Methods, properties and actions of a POU or interface, in file order. `prototypes`: an
// interface's, without bodies.
void Importer::read_members(const XmlFile& f, const pugi::xml_node& owner, const std::string& owner_what,
                            bool prototypes, Unit& u) {
  for (pugi::xml_node m : owner.children()) {
    if (m.type() != pugi::node_element) continue;
    std::string_view kind = m.name();
    const std::string name = m.attribute("Name").value();
    SourceLoc at = loc_of(f, m);
    if (kind == "Method") {
      const std::string what = "METHOD '" + name + "' of " + owner_what;
      if (!copy_declaration(f, m, what, u, true)) continue;
      if (!prototypes) copy_body(f, m, what, u);
      u.synth("END_METHOD", f.path, at);
    } else if (kind == "Property") {
      read_property(f, m, prototypes, u);
    } else if (kind == "Action") {
      // An action runs on the instance's variables, without parameters or locals of its
      // own, called as inst.A() or A(): a METHOD without declarations does the same.
      const std::string what = "ACTION '" + name + "' of " + owner_what;
      if (!is_identifier(name)) {
        diags_.error(kNotTwinCat, at, what + ": the name is not an identifier");
        continue;
      }
      u.synth("METHOD " + name, f.path, at);
      copy_body(f, m, what, u);
      u.synth("END_METHOD", f.path, at);
    }
  }
}

// <Property> with its declaration (PROPERTY P : T) and <Get>/<Set> accessors, each with a
// declaration (its VAR blocks) and a body.
void Importer::read_property(const XmlFile& f, const pugi::xml_node& prop, bool prototype, Unit& u) {
  const std::string what = "PROPERTY '" + std::string(prop.attribute("Name").value()) + "'";
  if (!copy_declaration(f, prop, what, u, true)) return;
  for (pugi::xml_node acc : prop.children()) {
    std::string_view kind = acc.name();
    if (kind != "Get" && kind != "Set") continue;
    const bool get = kind == "Get";
    SourceLoc at = loc_of(f, acc);
    u.synth(get ? "GET" : "SET", f.path, at);
    copy_declaration(f, acc, std::string(get ? "GET" : "SET") + " of " + what, u, false);
    if (!prototype) copy_body(f, acc, std::string(get ? "GET" : "SET") + " of " + what, u);
    u.synth(get ? "END_GET" : "END_SET", f.path, at);
  }
  u.synth("END_PROPERTY", f.path, loc_of(f, prop));
}

// <POU>: a PROGRAM, FUNCTION_BLOCK or FUNCTION; the declaration holds the header and the
// variable blocks, the implementation the statements; END_xxx is implicit.
void Importer::read_pou(const XmlFile& f, const pugi::xml_node& pou) {
  const std::string name = pou.attribute("Name").value();
  const std::string what = "POU '" + name + "'";
  pugi::xml_node decl = pou.child("Declaration");
  const std::string kw = first_keyword(decl.child_value());
  const char* end = kw == "PROGRAM" ? "END_PROGRAM" : kw == "FUNCTION_BLOCK" ? "END_FUNCTION_BLOCK"
                    : kw == "FUNCTION" ? "END_FUNCTION" : nullptr;
  if (!decl) {
    diags_.error(kNotTwinCat, loc_of(f, pou), what + " has no <Declaration>");
    return;
  }
  if (!end) {
    // The text after the keyword is the front end's to judge; the importer only needs the
    // closing keyword.
    diags_.error(kNotTwinCat, loc_of(f, decl),
                 what + ": the declaration does not start with PROGRAM, FUNCTION_BLOCK or FUNCTION" +
                     (kw.empty() ? std::string() : " (found '" + kw + "')"));
    return;
  }
  Unit u;
  copy_text(f, decl, u);
  copy_body(f, pou, what, u);
  read_members(f, pou, what, false, u);
  u.synth(end, f.path, loc_of(f, pou));
  add_unit(f.path, name, u);
}

// <Itf>: an INTERFACE with method and property prototypes.
void Importer::read_itf(const XmlFile& f, const pugi::xml_node& itf) {
  const std::string name = itf.attribute("Name").value();
  const std::string what = "interface '" + name + "'";
  Unit u;
  if (!copy_declaration(f, itf, what, u, true)) return;
  read_members(f, itf, what, true, u);
  u.synth("END_INTERFACE", f.path, loc_of(f, itf));
  add_unit(f.path, name, u);
}

// <DUT> (TYPE ... END_TYPE) and <GVL> (VAR_GLOBAL ... END_VAR): the declaration is the
// whole unit. A GVL's unit is named after it: qualified access (GVL.x) uses that name.
void Importer::read_declaration_only(const XmlFile& f, const pugi::xml_node& obj, const char* what) {
  const std::string name = obj.attribute("Name").value();
  Unit u;
  if (!copy_declaration(f, obj, std::string(what) + " '" + name + "'", u, true)) return;
  add_unit(f.path, name, u);
}

// <Task Name><CycleTime>us</CycleTime><Priority>n</Priority><PouCall><Name>MAIN</Name>...
void Importer::read_task(const XmlFile& f, const pugi::xml_node& task) {
  Task t;
  t.name = task.attribute("Name").value();
  t.path = f.path;
  t.loc = loc_of(f, task);
  const std::string what = "task '" + t.name + "'";
  if (!is_identifier(t.name)) {
    diags_.error(kBadTask, t.loc, what + ": the name is not an identifier");
    return;
  }
  auto number = [&](const char* tag, uint64_t max, uint64_t* out) {
    pugi::xml_node n = task.child(tag);
    if (!n) {
      diags_.error(kBadTask, t.loc, what + " has no <" + tag + ">");
      return false;
    }
    std::string v = n.child_value();
    v.erase(0, v.find_first_not_of(" \t\r\n"));
    v.erase(v.find_last_not_of(" \t\r\n") + 1);
    uint64_t x = 0;
    bool ok = !v.empty() && v.size() <= 19 && std::all_of(v.begin(), v.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (ok) x = std::stoull(v);
    if (!ok || x > max) {
      diags_.error(kBadTask, loc_of(f, n), what + ": <" + tag + "> '" + v + "' is not a whole number from 0 to " +
                                               std::to_string(max));
      return false;
    }
    *out = x;
    return true;
  };
  uint64_t prio = 0;
  // CycleTime is in microseconds; a day is far beyond any PLC task.
  if (!number("CycleTime", 86'400'000'000ULL, &t.cycle_us) || !number("Priority", 255, &prio)) return;
  if (t.cycle_us == 0) {
    diags_.error(kBadTask, loc_of(f, task.child("CycleTime")), what + ": a cycle time of 0 (free-running) is not supported");
    return;
  }
  t.priority = static_cast<int64_t>(prio);
  for (pugi::xml_node call : task.children("PouCall")) {
    pugi::xml_node n = call.child("Name");
    std::string program = n.child_value();
    SourceLoc at = loc_of(f, n ? n : call);
    if (!is_identifier(program)) {
      diags_.error(kBadTask, at, what + ": PouCall '" + program + "' is not a program name");
      continue;
    }
    t.calls.push_back(TaskCall{program, at, f.path});
  }
  tasks_.push_back(std::move(t));
}

void Importer::add_unit(const std::string& file_path, const std::string& object, Unit& u) {
  if (u.empty()) return;
  // Named as the object inside its file; the stem is the object's name (a GVL's scope).
  std::string name = file_path + "/" + identifier(object, fs::path(file_path).stem().string()) + ".st";
  units_->push_back(sm_.add_generated(std::move(name), u.take_text(), u.take_origins()));
}

// The project's tasks as one CONFIGURATION: each task calls its programs, whose instances
// bear the program's name (MAIN.x, as TwinCAT names them).
void Importer::add_configuration(const std::string& path, SourceLoc loc, const std::string& name) {
  Unit u;
  u.synth("CONFIGURATION " + name, path, loc);
  u.synth("RESOURCE PLC ON PLC", path, loc);
  std::set<std::string> called;
  for (const Task& t : tasks_) {
    std::string interval = t.cycle_us % 1000 == 0 ? std::to_string(t.cycle_us / 1000) + "ms" : std::to_string(t.cycle_us) + "us";
    u.synth("TASK " + t.name + " (INTERVAL := T#" + interval + ", PRIORITY := " + std::to_string(t.priority) + ");",
            t.path, t.loc);
  }
  for (const Task& t : tasks_) {
    for (const TaskCall& c : t.calls) {
      // TwinCAT runs one instance of a program in every task that calls it; plcfi gives
      // each PROGRAM ... WITH its own instance, which is not the same program.
      if (!called.insert(canon(c.program)).second) {
        diags_.error(kBadTask, c.loc, "program '" + c.program + "' is called by more than one task: not supported");
        continue;
      }
      u.synth("PROGRAM " + c.program + " WITH " + t.name + " : " + c.program + ";", c.path, c.loc);
    }
  }
  u.synth("END_RESOURCE", path, loc);
  u.synth("END_CONFIGURATION", path, loc);
  std::string unit_name = path + "/" + name + ".st";
  units_->push_back(sm_.add_generated(std::move(unit_name), u.take_text(), u.take_origins()));
  tasks_.clear();
}

}  // namespace

bool import_twincat(const std::string& path, SourceManager& sm, DiagEngine& diags, std::vector<uint32_t>* units,
                    std::vector<LibraryParam>* params) {
  const size_t errors_before = diags.error_count();
  Importer imp(sm, diags, units, params);
  imp.run(path);
  return diags.error_count() == errors_before;
}

}  // namespace plcfi::st
