// Engine facade: building from files, variable handles, value formatting, disassembly,
// coverage reports and trap descriptions.
#include "engine.hpp"
#include "vm/memory.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "import/import.hpp"
#include "syntax/parser.hpp"
#include "vm/natives.hpp"
#include "vm/wide.hpp"

namespace plcfi::st {

namespace {

// The program's runtime locations (traps, coverage, control-flow branches, tasks) in units
// imported from a project file are moved to where their text is in that file, as their
// compile-time diagnostics are.
void map_imported(Application& app, const SourceManager& sm, const std::set<uint32_t>& imported) {
  auto map = [&](SourceLoc& loc) {
    if (imported.count(loc.file)) loc = sm.origin(loc);
  };
  for (auto& entry : app.lines) map(entry.second);
  for (auto& branch : app.branches) map(branch.loc);
  for (auto& task : app.tasks) map(task.loc);
}

// A test library comes with the application when a source names its function block
// (TcUnit: FB_TestSuite; FB_ASSERT), unless a source declares one of that name itself (a
// copy of the library's sources in the project). key: the name in lower case.
bool uses_library(const SourceManager& sm, const std::vector<uint32_t>& files, const std::string& key) {
  bool named = false;
  for (uint32_t f : files) {
    if (is_library_path(sm.file(f).path)) continue;
    const std::string& text = sm.file(f).text;
    for (auto it = text.begin();; ++it) {
      it = std::search(it, text.end(), key.begin(), key.end(),
                       [](char a, char k) { return std::tolower(static_cast<unsigned char>(a)) == k; });
      if (it == text.end()) break;
      named = true;
      // Declared here: FUNCTION_BLOCK [modifiers] FB_TestSuite, i.e. the word before it
      // (past blanks) is FUNCTION_BLOCK or a modifier that only follows it.
      auto word_end = it;
      while (word_end != text.begin() && std::isspace(static_cast<unsigned char>(word_end[-1]))) --word_end;
      auto word_begin = word_end;
      while (word_begin != text.begin() && (std::isalnum(static_cast<unsigned char>(word_begin[-1])) || word_begin[-1] == '_')) --word_begin;
      const std::string before(word_begin, word_end);
      if (iequals(before, "FUNCTION_BLOCK") || iequals(before, "ABSTRACT") || iequals(before, "PUBLIC") ||
          iequals(before, "FINAL") || iequals(before, "INTERNAL"))
        return false;
    }
  }
  return named;
}

// Where `word` stands in text as a whole identifier (any case), from `from`; npos if not.
size_t find_word(const std::string& text, std::string_view word, size_t from = 0) {
  auto ident = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (size_t at = from; at + word.size() <= text.size(); ++at) {
    if (!iequals(std::string_view(text).substr(at, word.size()), word)) continue;
    if ((at > 0 && ident(text[at - 1])) || (at + word.size() < text.size() && ident(text[at + word.size()]))) continue;
    return at;
  }
  return std::string::npos;
}

// Whether the sources name `name` and do not declare it themselves (the name followed by
// ':' but not ':=', or after FUNCTION/FUNCTION_BLOCK).
bool named_not_declared(const SourceManager& sm, const std::vector<uint32_t>& files, const char* name) {
  bool named = false, declared = false;
  for (uint32_t f : files) {
    if (is_library_path(sm.file(f).path)) continue;
    const std::string& src = sm.file(f).text;
    for (size_t at = find_word(src, name); at != std::string::npos; at = find_word(src, name, at + 1)) {
      named = true;
      size_t k = at + std::strlen(name);
      while (k < src.size() && std::isspace(static_cast<unsigned char>(src[k]))) ++k;
      if (k < src.size() && src[k] == ':' && (k + 1 >= src.size() || src[k + 1] != '=')) declared = true;
      size_t b = at;
      while (b > 0 && std::isspace(static_cast<unsigned char>(src[b - 1]))) --b;
      for (std::string_view kw : {"FUNCTION_BLOCK", "FUNCTION"})
        if (b >= kw.size() && iequals(std::string_view(src).substr(b - kw.size(), kw.size()), kw)) declared = true;
    }
  }
  return named && !declared;
}

// The Tc2 data types the sources name and do not declare, as one library text; empty
// when there are none.
std::string tc2_library(const SourceManager& sm, const std::vector<uint32_t>& files) {
  std::string text;
  for (const Tc2Type& t : tc2_types())
    if (named_not_declared(sm, files, t.name)) text += t.source;
  return text;
}

// The same for the items of Tc2_System, each with the item its source uses.
std::string tc2_system_library(const SourceManager& sm, const std::vector<uint32_t>& files) {
  std::set<std::string> wanted;
  for (const Tc2Item& item : tc2_system_items())
    if (named_not_declared(sm, files, item.name)) {
      wanted.insert(item.name);
      if (item.needs) wanted.insert(item.needs);
    }
  std::string text;
  for (const Tc2Item& item : tc2_system_items())
    if (wanted.count(item.name)) text += item.source;
  return text;
}

// After a parse error, the POUs that parsed are still type-checked, so that one broken
// POU does not hide the errors of the others (a compiler would go on the same way). The
// POUs holding a parse error are set aside for this pass, and a POU whose errors name one
// of them (its errors follow from the broken one) is left out of the report. A parse
// error outside every POU (a TYPE, a VAR_GLOBAL, a test) stops here: too much of what
// the rest needs is missing to say anything reliable.
void check_the_rest(Build& b, const CompileOptions& opt) {
  auto before = [](SourceLoc a, SourceLoc c) { return std::tie(a.line, a.col) < std::tie(c.line, c.col); };
  // Errors are reported where the user's file has them: a POU imported from XML (TwinCAT,
  // PLCopen) is compared there too, from its declaration on.
  auto at = [&](SourceLoc l) { return b.sm.origin(l); };
  auto holds = [&](const Pou& p, SourceLoc l) {
    const SourceLoc start = at(p.loc), end = at(p.end_loc);
    if (l.file != start.file || before(l, start)) return false;
    if (p.end_loc.valid() && end.file == start.file && !before(end, start)) return !before(end, l);
    // An end the importer wrote (at the XML element, before the declaration): the POU
    // reaches to the next one in the same file (its body in LD or SFC, say).
    for (const auto& u : b.units)
      for (const auto& q : u->pous)
        if (q && q.get() != &p) {
          const SourceLoc next = at(q->loc);
          if (next.file == start.file && before(start, next) && !before(l, next)) return false;
        }
    return true;
  };
  std::vector<SourceLoc> errors;
  for (const Diagnostic& d : b.diags.all())
    if (d.severity == Severity::Error) errors.push_back(d.loc);
  if (errors.empty() || b.diags.error_count() > b.diags.all().size()) return;
  struct SetAside {
    CompilationUnit* unit;
    size_t index;
    PouPtr pou;
  };
  std::vector<SetAside> aside;
  std::vector<std::string> broken;  // names of the POUs set aside, upper case
  for (SourceLoc e : errors) {
    bool found = false;
    for (auto& u : b.units)
      for (const auto& p : u->pous)
        if (p && holds(*p, e)) found = true;
    if (!found) return;
  }
  for (auto& u : b.units)
    for (size_t i = u->pous.size(); i-- > 0;) {
      const Pou& p = *u->pous[i];
      if (std::none_of(errors.begin(), errors.end(), [&](SourceLoc e) { return holds(p, e); })) continue;
      broken.push_back(canon(p.name.text));
      aside.push_back({u.get(), i, std::move(u->pous[i])});
      u->pous.erase(u->pous.begin() + static_cast<ptrdiff_t>(i));
    }
  DiagEngine rest(b.sm);
  rest.set_warnings(false);
  {
    std::vector<const CompilationUnit*> units;
    for (const auto& u : b.units) units.push_back(u.get());
    std::vector<const TestFile*> tests;
    for (const auto& t : b.tests) tests.push_back(t.get());
    (void)compile(b.sm, units, tests, rest, opt);
  }
  // Put the broken POUs back where they were (reverse order of removal).
  for (auto it = aside.rbegin(); it != aside.rend(); ++it)
    it->unit->pous.insert(it->unit->pous.begin() + static_cast<ptrdiff_t>(it->index), std::move(it->pou));
  auto names_broken = [&](const std::string& message) {
    const std::string m = canon(message);
    return std::any_of(broken.begin(), broken.end(), [&](const std::string& n) { return m.find("'" + n + "'") != std::string::npos; });
  };
  // The POU (by its position) each error of the second pass lies in; -1: none.
  auto pou_of = [&](SourceLoc l) -> const Pou* {
    for (const auto& u : b.units)
      for (const auto& p : u->pous)
        if (holds(*p, l)) return p.get();
    return nullptr;
  };
  std::set<const Pou*> tainted;
  for (const Diagnostic& d : rest.all())
    if (d.severity == Severity::Error && names_broken(d.message)) tainted.insert(pou_of(d.loc));
  for (const Diagnostic& d : rest.all()) {
    if (d.severity != Severity::Error || names_broken(d.message) || tainted.count(pou_of(d.loc))) continue;
    Diagnostic& copy = b.diags.error(d.code, d.loc, d.message);
    copy.notes = d.notes;
  }
}

std::unique_ptr<Build> finish(std::unique_ptr<Build> b, std::vector<uint32_t> files, const CompileOptions& opt,
                              const GeneratedSources& late, const std::set<uint32_t>& imported = {}) {
  if (opt.dialect == Dialect::Codesys) {
    if (std::string tc2 = tc2_library(b->sm, files); !tc2.empty()) files.insert(files.begin() + 1, b->sm.add("<Tc2>", tc2));
    if (std::string sys = tc2_system_library(b->sm, files); !sys.empty())
      files.insert(files.begin() + 1, b->sm.add("<Tc2_System>", sys));
  }
  if (uses_library(b->sm, files, "fb_testsuite")) {
    // TcUnit's parameters: the projects' settings (each checked at its place), then the
    // command line's.
    std::vector<std::pair<std::string, std::string>> values;
    for (const auto& p : b->library_params) {
      if (!iequals(p.list, "GVL_Param_TcUnit")) continue;
      if (std::string why = tcunit_param_error(p.key, p.value); !why.empty()) b->diags.error("ST625", p.loc, why);
      else values.emplace_back(p.key, p.value);
    }
    for (const auto& kv : opt.tcunit_params) values.push_back(kv);
    files.insert(files.begin() + 1, b->sm.add("<TcUnit>/GVL_Param_TcUnit", tcunit_params_source(values)));
    files.insert(files.begin() + 1, b->sm.add("<TcUnit>", tcunit_source()));
  }
  if (uses_library(b->sm, files, "fb_assert")) files.insert(files.begin() + 1, b->sm.add("<FB_ASSERT>", fb_assert_source()));
  for (uint32_t f : files) {
    if (is_test_file(b->sm, f)) b->tests.push_back(parse_test_file(b->sm, f, b->diags));
    else b->units.push_back(parse_unit(b->sm, f, b->diags));
  }
  if (b->diags.has_errors() && b->io_errors.empty()) check_the_rest(*b, opt);
  if (b->diags.has_errors() || !b->io_errors.empty()) return b;
  std::vector<const CompilationUnit*> units;
  for (const auto& u : b->units) units.push_back(u.get());
  std::vector<const TestFile*> tests;
  for (const auto& t : b->tests) tests.push_back(t.get());
  b->app = compile(b->sm, units, tests, b->diags, opt);
  if (b->app && !imported.empty()) map_imported(*b->app, b->sm, imported);
  if (b->app && !late.empty() && !link_generated(*b, late, opt)) b->app.reset();
  return b;
}

uint32_t add_stdlib(Build& b, Dialect d) { return b.sm.add("<stdlib>", stdlib_source(d)); }
}  // namespace

std::unique_ptr<Build> build_files(const std::vector<std::string>& paths, const CompileOptions& opt, const GeneratedSources& late) {
  auto b = std::make_unique<Build>();
  b->diags.set_warnings(opt.warnings);
  std::vector<uint32_t> files{add_stdlib(*b, opt.dialect)};
  std::set<uint32_t> imported;  // units generated by an importer
  auto read = [&](const std::string& p) {
    uint32_t idx = 0;
    std::string err;
    if (!b->sm.load(p, &idx, &err)) {
      b->io_errors.push_back(err);
      return;
    }
    // A project file is not ST: its importer adds the units it holds (the file itself
    // stays loaded, for the messages that point into it; an unreadable one was an I/O
    // error above, like any other).
    if (InputKind kind = input_kind(p); kind != InputKind::St) {
      const size_t first = files.size();
      if (kind == InputKind::PlcopenXml) import_plcopen(p, b->sm, b->diags, &files);
      else import_twincat(p, b->sm, b->diags, &files, &b->library_params);
      imported.insert(files.begin() + static_cast<ptrdiff_t>(first), files.end());
      return;
    }
    files.push_back(idx);
  };
  // Libraries first, as a PLC project's references come before its own objects; every
  // file they bring (the project files read and the units generated from them) is theirs.
  const auto first_library_file = static_cast<uint32_t>(b->sm.size());
  for (const auto& p : opt.library_files) read(p);
  b->sm.mark_library(first_library_file);
  for (const auto& p : paths) read(p);
  return finish(std::move(b), files, opt, late, imported);
}

std::unique_ptr<Build> build_sources(const NamedSources& sources, const CompileOptions& opt, const GeneratedSources& late) {
  auto b = std::make_unique<Build>();
  b->diags.set_warnings(opt.warnings);
  std::vector<uint32_t> files{add_stdlib(*b, opt.dialect)};
  for (const auto& [name, text] : sources) files.push_back(b->sm.add(name, text));
  return finish(std::move(b), files, opt, late);
}

bool link_generated(Build& b, const GeneratedSources& late, const CompileOptions& opt) {
  if (!b.app) return false;
  const size_t first = b.late.size();
  for (const auto& g : late) b.late.push_back(parse_unit(b.sm, b.sm.add_generated(g.name, g.text, g.origins), b.diags));
  if (b.diags.has_errors()) return false;
  std::vector<const CompilationUnit*> units;
  for (size_t i = first; i < b.late.size(); ++i) units.push_back(b.late[i].get());
  return link_units(*b.app, b.sm, units, b.diags, opt);
}

// ------------------------------------------------------------------ handles

namespace {
struct PathPart {
  std::string name;
  std::vector<int64_t> indices;
  bool is_bit = false;
  uint32_t bit = 0;
};

bool split_path(std::string_view path, std::vector<PathPart>* out, std::string* err) {
  size_t i = 0;
  auto fail = [&](const std::string& msg) {
    *err = "path '" + std::string(path) + "': " + msg;
    return false;
  };
  while (i < path.size()) {
    PathPart part;
    if (std::isdigit(static_cast<unsigned char>(path[i]))) {
      size_t j = i;
      while (j < path.size() && std::isdigit(static_cast<unsigned char>(path[j]))) ++j;
      part.is_bit = true;
      // A bit of at most a LWORD: two digits; longer is out of range, not a number to read.
      if (j - i > 2) return fail("bit number at column " + std::to_string(i + 1) + " is out of range (0..63)");
      part.bit = static_cast<uint32_t>(std::stoul(std::string(path.substr(i, j - i))));
      i = j;
    } else {
      size_t j = i;
      while (j < path.size() && (std::isalnum(static_cast<unsigned char>(path[j])) || path[j] == '_')) ++j;
      if (j == i) return fail("expected a name at column " + std::to_string(i + 1));
      part.name = std::string(path.substr(i, j - i));
      i = j;
      while (i < path.size() && path[i] == '[') {
        ++i;
        for (;;) {
          size_t k = i;
          if (k < path.size() && (path[k] == '-' || path[k] == '+')) ++k;
          size_t d = k;
          while (k < path.size() && std::isdigit(static_cast<unsigned char>(path[k]))) ++k;
          if (k == d) return fail("expected a constant index at column " + std::to_string(i + 1));
          if (k - d > 18) return fail("index at column " + std::to_string(i + 1) + " is out of range");
          part.indices.push_back(std::stoll(std::string(path.substr(i, k - i))));
          i = k;
          while (i < path.size() && path[i] == ' ') ++i;
          if (i < path.size() && path[i] == ',') {
            ++i;
            while (i < path.size() && path[i] == ' ') ++i;
            continue;
          }
          if (i < path.size() && path[i] == ']') {
            ++i;
            break;
          }
          return fail("expected ',' or ']' at column " + std::to_string(i + 1));
        }
      }
    }
    out->push_back(std::move(part));
    if (i < path.size()) {
      if (path[i] != '.') return fail("unexpected '" + std::string(1, path[i]) + "' at column " + std::to_string(i + 1));
      ++i;
      if (i == path.size()) return fail("ends with '.'");
    }
  }
  if (out->empty()) return fail("empty");
  return true;
}

bool parse_direct(const Application& app, std::string_view text, VarHandle* h, std::string* err) {
  // %[IQM][XBWDL]?n(.b)?
  std::string t = canon(text);
  if (t.size() < 3 || t[0] != '%') {
    *err = "'" + std::string(text) + "' is not a direct address";
    return false;
  }
  const ImageArea* area = app.image(t[1]);
  if (!area) {
    *err = "'" + std::string(text) + "': the area must be I, Q or M";
    return false;
  }
  size_t i = 2;
  char size = 'X';
  if (i < t.size() && std::string("XBWDL").find(t[i]) != std::string::npos) size = t[i++];
  std::vector<uint64_t> parts;
  while (i < t.size()) {
    size_t j = i;
    while (j < t.size() && std::isdigit(static_cast<unsigned char>(t[j]))) ++j;
    if (j == i || j - i > 9) {
      *err = "'" + std::string(text) + "' is not a valid address";
      return false;
    }
    parts.push_back(std::stoull(t.substr(i, j - i)));
    i = j;
    if (i < t.size()) {
      if (t[i] != '.') {
        *err = "'" + std::string(text) + "' is not a valid address";
        return false;
      }
      ++i;
    }
  }
  uint32_t unit = size == 'B' || size == 'X' ? 1 : size == 'W' ? 2 : size == 'D' ? 4 : 8;
  bool bit = size == 'X';
  if ((bit && (parts.size() != 2 || parts[1] > 7)) || (!bit && parts.size() != 1)) {
    *err = "'" + std::string(text) + "': " + (bit ? "a bit address is %" + std::string(1, t[1]) + "Xbyte.bit with bit 0..7" : "a byte/word address has one number");
    return false;
  }
  uint64_t byte = parts[0] * unit;
  if (byte + unit > area->size) {
    *err = "'" + std::string(text) + "' is outside the %" + std::string(1, t[1]) + " image (" + std::to_string(area->size) + " bytes)";
    return false;
  }
  h->addr = area->addr + static_cast<uint32_t>(byte);
  h->is_bit = bit;
  h->bit = bit ? static_cast<uint8_t>(parts[1]) : 0;
  TypeKind k = bit ? TypeKind::Bool : size == 'B' ? TypeKind::Byte : size == 'W' ? TypeKind::Word : size == 'D' ? TypeKind::DWord : TypeKind::LWord;
  h->type = app.types->elementary(k);
  return true;
}
}  // namespace

std::optional<VarHandle> resolve(const Application& app, std::string_view path, std::string* err) {
  VarHandle h;
  h.path = std::string(path);
  if (!path.empty() && path[0] == '%') {
    if (!parse_direct(app, path, &h, err)) return std::nullopt;
    return h;
  }
  std::vector<PathPart> parts;
  if (!split_path(path, &parts, err)) return std::nullopt;
  size_t i = 0;
  const Type* t = nullptr;
  const PouInfo* pou = nullptr;
  auto fail = [&](const std::string& msg) -> std::optional<VarHandle> {
    *err = "path '" + std::string(path) + "': " + msg;
    return std::nullopt;
  };
  // First part: a program instance (or a linked unit's observer), a global, or a
  // global's scope (GVL, configuration).
  for (const auto* list : {&app.programs, &app.observers})
    for (const auto& pi : *list)
      if (i == 0 && iequals(pi.name, parts[0].name) && parts[0].indices.empty()) {
        t = pi.pou->type;
        pou = pi.pou;
        h.addr = pi.addr;
        i = 1;
      }
  auto from_sym = [&](const Symbol* s) {
    t = s->type;
    h.addr = s->offset;
    if (s->where == Where::AbsBit) {
      h.is_bit = true;
      h.bit = s->bit;
    }
  };
  if (!t) {
    for (const auto& g : app.globals)
      if (iequals(g.sym->name, parts[0].name)) {
        from_sym(g.sym);
        i = 1;
        break;
      }
  }
  if (!t && parts.size() > 1) {
    for (const auto& g : app.globals)
      if (iequals(g.scope, parts[0].name) && iequals(g.sym->name, parts[1].name)) {
        from_sym(g.sym);
        i = 2;
        break;
      }
  }
  if (!t) {
    std::string known;
    for (const auto& pi : app.programs) known += (known.empty() ? "" : ", ") + pi.name;
    return fail("no program instance or global variable named '" + parts[0].name + "'" +
                (known.empty() ? "" : " (program instances: " + known + ")"));
  }
  // Indices of the first part (a global array).
  auto apply_indices = [&](const PathPart& p) -> bool {
    if (p.indices.empty()) return true;
    if (t->kind != TypeKind::Array || p.indices.size() != t->dims.size()) {
      *err = "path '" + std::string(path) + "': '" + p.name + "' needs " +
             (t->kind == TypeKind::Array ? std::to_string(t->dims.size()) + " index(es)" : "no index (not an array)");
      return false;
    }
    uint64_t stride = t->elem->size, off = 0;
    for (size_t d = t->dims.size(); d-- > 0;) {
      int64_t ix = p.indices[d];
      if (ix < t->dims[d].lo || ix > t->dims[d].hi) {
        *err = "path '" + std::string(path) + "': index " + std::to_string(ix) + " outside " + std::to_string(t->dims[d].lo) + ".." +
               std::to_string(t->dims[d].hi);
        return false;
      }
      off += static_cast<uint64_t>(ix - t->dims[d].lo) * stride;
      stride *= static_cast<uint64_t>(t->dims[d].hi - t->dims[d].lo + 1);
    }
    h.addr += static_cast<uint32_t>(off);
    t = t->elem;
    return true;
  };
  if (i > 0 && !apply_indices(parts[i - 1])) return std::nullopt;
  for (; i < parts.size(); ++i) {
    const PathPart& p = parts[i];
    if (h.is_bit) return fail("a single bit has no members");
    if (p.is_bit) {
      if (!t->is_integer() && !t->is_bitstring()) return fail("bit access needs an integer or bit string, not " + t->name);
      if (p.bit >= t->bit_width()) return fail("bit " + std::to_string(p.bit) + " does not exist in " + t->name);
      h.addr += p.bit / 8;  // little-endian: bit n is in byte n / 8
      h.bit = static_cast<uint8_t>(p.bit % 8);
      h.is_bit = true;
      t = app.types->elementary(TypeKind::Bool);
      continue;
    }
    const Field* f = (t->kind == TypeKind::Struct || t->kind == TypeKind::Pou) ? t->field(p.name) : nullptr;
    if (!f && t->kind == TypeKind::Pou && t->pou) {
      // Located variables of a program live in the I/O image, not in the instance.
      if (const Symbol* s = t->pou->find_var(p.name); s && (s->where == Where::Abs || s->where == Where::AbsBit)) {
        from_sym(s);
        if (!apply_indices(p)) return std::nullopt;
        continue;
      }
    }
    if (!f) return fail("'" + t->name + "' has no member '" + p.name + "'");
    if (f->type->kind == TypeKind::Ref && t->kind == TypeKind::Pou) {
      const Symbol* s = t->pou ? t->pou->find_var(p.name) : nullptr;
      if (s && s->where == Where::InOut) return fail("'" + p.name + "' is a VAR_IN_OUT (a reference); name the variable it refers to");
    }
    h.addr += f->offset;
    t = f->type;
    if (!apply_indices(p)) return std::nullopt;
  }
  (void)pou;
  h.type = t;
  return h;
}

bool read_bool(const Machine& m, const VarHandle& h) {
  if (h.is_bit) return (m.mem()[h.addr] >> h.bit) & 1u;
  if (h.type->kind == TypeKind::Bool) return m.mem()[h.addr] != 0;  // the common case, read every scan by watchers
  return read_int(m, h) != 0;
}

int64_t read_int(const Machine& m, const VarHandle& h) {
  if (h.is_bit) return (m.mem()[h.addr] >> h.bit) & 1u;
  const uint8_t* p = m.mem() + h.addr;
  switch (h.type->storage()) {
    case Storage::I8: return load_as<int8_t>(p);
    case Storage::I16: return load_as<int16_t>(p);
    case Storage::I32: return load_as<int32_t>(p);
    case Storage::I64: return load_as<int64_t>(p);
    case Storage::U8: return load_as<uint8_t>(p);
    case Storage::U16: return load_as<uint16_t>(p);
    case Storage::U32: return load_as<uint32_t>(p);
    case Storage::U64: return static_cast<int64_t>(load_as<uint64_t>(p));
    case Storage::F32: return static_cast<int64_t>(std::nearbyint(load_as<float>(p)));
    case Storage::F64: return static_cast<int64_t>(std::nearbyint(load_as<double>(p)));
    default: return 0;
  }
}

double read_real(const Machine& m, const VarHandle& h) {
  if (h.type->kind == TypeKind::Real) return load_as<float>(m.mem() + h.addr);
  if (h.type->kind == TypeKind::LReal) return load_as<double>(m.mem() + h.addr);
  if (h.type->storage() == Storage::U64) return static_cast<double>(load_as<uint64_t>(m.mem() + h.addr));
  return static_cast<double>(read_int(m, h));
}

void write_bool(Machine& m, const VarHandle& h, bool v) { write_int(m, h, v ? 1 : 0); }

void write_int(Machine& m, const VarHandle& h, int64_t v) {
  uint8_t* p = m.mem() + h.addr;
  if (h.is_bit) {
    auto mask = static_cast<uint8_t>(1u << h.bit);
    *p = static_cast<uint8_t>(v ? (*p | mask) : (*p & ~mask));
    return;
  }
  // The width decides for integers, enums, times and bits (the hot path of drivers and
  // monitors); only the REAL types convert.
  if (h.type->kind == TypeKind::Real) return store_as<float>(p, static_cast<float>(v));
  if (h.type->kind == TypeKind::LReal) return store_as<double>(p, static_cast<double>(v));
  switch (h.type->kind) {
    case TypeKind::String: case TypeKind::WString: case TypeKind::Array: case TypeKind::Struct: case TypeKind::Pou:
    case TypeKind::Void: return;
    default: break;
  }
  switch (h.type->size) {
    case 1: store_as<uint8_t>(p, static_cast<uint8_t>(h.type->kind == TypeKind::Bool ? v != 0 : v)); break;
    case 2: store_as<uint16_t>(p, static_cast<uint16_t>(v)); break;
    case 4: store_as<uint32_t>(p, static_cast<uint32_t>(v)); break;
    case 8: store_as<uint64_t>(p, static_cast<uint64_t>(v)); break;
    default: break;
  }
}

void write_real(Machine& m, const VarHandle& h, double v) {
  if (h.type->kind == TypeKind::Real) store_as<float>(m.mem() + h.addr, static_cast<float>(v));
  else if (h.type->kind == TypeKind::LReal) store_as<double>(m.mem() + h.addr, v);
  else write_int(m, h, static_cast<int64_t>(std::nearbyint(v)));
}

namespace {
std::string duration(int64_t ns) {
  std::string out = "T#";
  if (ns < 0) {
    out += '-';
    ns = -ns;
  }
  if (ns == 0) return out + "0s";
  static constexpr std::pair<int64_t, const char*> kUnits[] = {{86'400'000'000'000, "d"}, {3'600'000'000'000, "h"},
                                                               {60'000'000'000, "m"},     {1'000'000'000, "s"},
                                                               {1'000'000, "ms"},         {1'000, "us"},
                                                               {1, "ns"}};
  for (auto [u, n] : kUnits)
    if (ns >= u) {
      out += std::to_string(ns / u) + n;
      ns %= u;
    }
  return out;
}
}  // namespace

std::string format(const Machine& m, const VarHandle& h) {
  const Type* t = h.type;
  if (h.is_bit || t->kind == TypeKind::Bool) return read_bool(m, h) ? "TRUE" : "FALSE";
  const uint8_t* p = m.mem() + h.addr;
  switch (t->kind) {
    case TypeKind::Real: return fmt::format("{}", load_as<float>(p));
    case TypeKind::LReal: return fmt::format("{}", load_as<double>(p));
    case TypeKind::LTime:
      if (t->unsigned_count) return unsigned_duration_literal(load_as<uint64_t>(p));
      return duration(load_as<int64_t>(p));
    case TypeKind::Time: return duration(load_as<int64_t>(p));
    case TypeKind::Date: return date_literal(load_as<int64_t>(p));
    case TypeKind::TimeOfDay: return tod_literal(load_as<int64_t>(p));
    case TypeKind::DateTime: return dt_literal(load_as<int64_t>(p));
    case TypeKind::String: {
      const char* s = reinterpret_cast<const char*>(p);
      return "'" + std::string(s, strnlen(s, t->str_len)) + "'";
    }
    case TypeKind::WString: return "'" + utf16_to_utf8(load_wstring(p, t->str_len)) + "'";  // users read UTF-8
    case TypeKind::Enum: {
      int64_t v = read_int(m, h);
      for (const auto& [n, x] : t->enum_values)
        if (x == v) return n;
      return t->name + "#" + std::to_string(v);
    }
    case TypeKind::ULInt: case TypeKind::LWord: return std::to_string(load_as<uint64_t>(p));
    case TypeKind::Byte: case TypeKind::Word: case TypeKind::DWord: return fmt::format("16#{:X}", read_int(m, h));
    case TypeKind::Array: case TypeKind::Struct: case TypeKind::Pou: return "(" + t->name + ")";
    default: return std::to_string(read_int(m, h));
  }
}

bool write_text(Machine& m, const VarHandle& h, std::string_view text, std::string* err) {
  const Type* t = h.type;
  if (!t->is_elementary() && !t->is_string()) {
    *err = "cannot set " + h.path + ": " + t->name + " is not an elementary type";
    return false;
  }
  if (t->kind == TypeKind::Enum) {
    for (const auto& [n, v] : t->enum_values)
      if (iequals(n, text) || iequals(t->name + "#" + n, text)) {
        write_int(m, h, v);
        return true;
      }
  }
  SourceManager sm;
  uint32_t f = sm.add("<value>", std::string(text));
  DiagEngine diags(sm);
  ExprPtr e = parse_expression(sm, f, diags);
  if (!e || diags.has_errors()) {
    *err = "'" + std::string(text) + "' is not a valid ST literal for " + h.path;
    return false;
  }
  bool neg = false;
  const Expr* x = e.get();
  if (x->kind == ExprKind::Unary && static_cast<const UnaryExpr*>(x)->op == UnaryOp::Neg) {
    neg = true;
    x = static_cast<const UnaryExpr*>(x)->operand.get();
  }
  if (x->kind != ExprKind::Literal) {
    *err = "'" + std::string(text) + "' is not a literal (expected e.g. TRUE, 42, 1.5, T#2s, 'text')";
    return false;
  }
  const auto& l = static_cast<const LiteralExpr&>(*x);
  auto bad_kind = [&]() {
    *err = "'" + std::string(text) + "' does not fit " + h.path + " (" + t->name + ")";
    return false;
  };
  if (t->is_string()) {
    if (l.lit != LiteralKind::String && l.lit != LiteralKind::WString) return bad_kind();
    if (t->kind == TypeKind::WString) {  // the literal's UTF-8 as the WSTRING's UTF-16
      store_wstring(m.mem() + h.addr, t->str_len, utf8_to_utf16(l.str_value));
      return true;
    }
    size_t n = std::min<size_t>(l.str_value.size(), t->str_len);
    std::memcpy(m.mem() + h.addr, l.str_value.data(), n);
    m.mem()[h.addr + n] = 0;
    return true;
  }
  if (t->kind == TypeKind::Bool || h.is_bit) {
    if (l.lit == LiteralKind::Bool || (l.lit == LiteralKind::Int && l.int_value <= 1 && !neg)) {
      write_bool(m, h, l.int_value != 0);
      return true;
    }
    return bad_kind();
  }
  if (t->is_real()) {
    if (l.lit != LiteralKind::Real && l.lit != LiteralKind::Int) return bad_kind();
    double v = l.lit == LiteralKind::Real ? l.real_value : static_cast<double>(l.int_value);
    write_real(m, h, neg ? -v : v);
    return true;
  }
  if (t->is_time_like()) {
    if (l.lit == LiteralKind::Int) return bad_kind();  // durations need T#
    if (l.lit != LiteralKind::Time && l.lit != LiteralKind::Date && l.lit != LiteralKind::TimeOfDay && l.lit != LiteralKind::DateTime)
      return bad_kind();
    write_int(m, h, neg ? -l.time_ns : l.time_ns);
    return true;
  }
  // TRUE/FALSE fit a bit string (a BYTE of one bit), not an integer: INT := TRUE is a type error.
  if (l.lit != LiteralKind::Int && !(l.lit == LiteralKind::Bool && t->is_bitstring())) return bad_kind();
  int64_t v = neg ? -static_cast<int64_t>(l.int_value) : static_cast<int64_t>(l.int_value);
  // Range check against the type.
  int64_t lo = 0, hi = 0;
  switch (t->storage()) {
    case Storage::I8: lo = INT8_MIN; hi = INT8_MAX; break;
    case Storage::I16: lo = INT16_MIN; hi = INT16_MAX; break;
    case Storage::I32: lo = INT32_MIN; hi = INT32_MAX; break;
    case Storage::I64: lo = INT64_MIN; hi = INT64_MAX; break;
    case Storage::U8: lo = 0; hi = UINT8_MAX; break;
    case Storage::U16: lo = 0; hi = UINT16_MAX; break;
    case Storage::U32: lo = 0; hi = UINT32_MAX; break;
    default: lo = 0; hi = INT64_MAX; break;
  }
  if (t->ranged) {
    lo = t->lo;
    hi = t->hi;
  }
  if (v < lo || v > hi) {
    *err = std::string(text) + " is outside the range of " + h.path + " (" + t->name + ": " + std::to_string(lo) + ".." + std::to_string(hi) + ")";
    return false;
  }
  write_int(m, h, v);
  return true;
}

// ------------------------------------------------------------------ listings

std::string disassemble(const Application& app, const Build* build) {
  // Entry points by pc, for headers.
  std::map<uint32_t, std::string> heads;
  for (const auto& p : app.pous) {
    if (p->is_stdlib || app.is_library_file(p->loc.file) || !p->compiled) continue;
    if (p->kind != PouKind::Interface && !p->is_test) heads[p->entry] = p->name;
    if (p->has_init) heads[p->init_entry] = p->name + " (FB_init of its instances)";
    if (p->has_exit) heads[p->exit_entry] = p->name + " (FB_exit of its instances)";
    for (const auto& m : p->methods)
      if (m->compiled && m->has_body) heads[m->entry] = p->name + "." + m->name;
  }
  if (app.has_init) heads[app.init_entry] = "FB_init of the application's instances";
  if (app.has_exit) heads[app.exit_entry] = "FB_exit of the application's instances";
  for (const auto& t : app.tests) {
    heads[t.setup_entry] = "TEST '" + t.name + "' (setup)";
    heads[t.body_entry] = "TEST '" + t.name + "'";
    heads[t.teardown_entry] = "TEST '" + t.name + "' (teardown)";
  }
  std::set<uint32_t> stdlib_ranges;
  std::string out;
  bool show = false;
  uint32_t last_line = 0, last_file = UINT32_MAX;
  for (uint32_t pc = 0; pc < app.code.size();) {
    auto h = heads.find(pc);
    if (h != heads.end()) {
      show = true;
      out += "\n" + h->second + ":\n";
      last_line = 0;
    } else {
      // Library bodies are not listed unless reached from a header.
      for (const auto& p : app.pous) {
        if (!p->compiled || !(p->is_stdlib || app.is_library_file(p->loc.file))) continue;
        if (p->entry == pc) show = false;
        for (const auto& m : p->methods)
          if (m->compiled && m->has_body && m->entry == pc) show = false;
      }
    }
    uint32_t len = op_length(&app.code[pc]);
    if (pc + len > app.code.size()) break;
    if (show) {
      SourceLoc loc = app.loc_of(pc);
      if (loc.valid() && (loc.line != last_line || loc.file != last_file)) {
        std::string src;
        if (build && loc.file < build->sm.size()) src = std::string(build->sm.file(loc.file).line_text(loc.line));
        size_t start = src.find_first_not_of(" \t");
        out += fmt::format("  ; {}:{}  {}\n", app.file_paths[loc.file], loc.line, start == std::string::npos ? "" : src.substr(start));
        last_line = loc.line;
        last_file = loc.file;
      }
      const OpInfo& info = op_info(static_cast<Op>(app.code[pc]));
      std::string line = fmt::format("  {:6}  {:<10}", pc, info.name);
      for (uint32_t k = 1; k < len; ++k) line += fmt::format(" {}", app.code[pc + k]);
      if (static_cast<Op>(app.code[pc]) == Op::NATIVE) line += fmt::format("   ({})", native_name(app.code[pc + 1] & 0xffffu));
      out += line + "\n";
    }
    pc += len;
  }
  return out;
}

std::string coverage_report(const Application& app, const std::vector<uint64_t>& covered) {
  struct FileCov {
    size_t total = 0, taken = 0;
    std::vector<std::string> missed;
  };
  std::map<std::string, FileCov> files;
  for (size_t i = 0; i < app.branches.size(); ++i) {
    const auto& b = app.branches[i];
    if (b.loc.file >= app.file_paths.size() || app.is_library_file(b.loc.file)) continue;
    auto& fc = files[app.file_paths[b.loc.file]];
    ++fc.total;
    bool hit = i / 64 < covered.size() && ((covered[i / 64] >> (i % 64)) & 1u);
    if (hit) ++fc.taken;
    else fc.missed.push_back(fmt::format("{}:{}:{} {} in {}", app.file_paths[b.loc.file], b.loc.line, b.loc.col, b.kind, b.pou));
  }
  std::string out = "branch coverage:\n";
  for (const auto& [f, c] : files) {
    out += fmt::format("  {}: {}/{} branches ({:.0f}%)\n", f, c.taken, c.total, c.total ? 100.0 * c.taken / c.total : 100.0);
    for (const auto& m : c.missed) out += "    not taken: " + m + "\n";
  }
  if (files.empty()) out += "  (no branches)\n";
  return out;
}

const char* trap_code(TrapKind k) {
  switch (k) {
    case TrapKind::DivisionByZero: return "ST501";
    case TrapKind::IndexOutOfRange: return "ST502";
    case TrapKind::RangeError: return "ST503";
    case TrapKind::NullReference: return "ST504";
    case TrapKind::Watchdog: return "ST505";
    case TrapKind::CallDepth: return "ST506";
    case TrapKind::AssertFailed: return "ST507";
    case TrapKind::NotImplemented: return "ST508";
    case TrapKind::BadAddress: return "ST509";
    default: return "ST500";
  }
}

std::string describe_trap_kind(const Trap& t) {
  return fmt::format("runtime error[{}]: {}{}", trap_code(t.kind), trap_name(t.kind),
                     t.message.empty() || t.message == trap_name(t.kind) ? "" : ": " + t.message);
}

std::string describe_trap(const Application& app, const Trap& t) {
  return app.where(t.loc) + ": " + describe_trap_kind(t);
}

}  // namespace plcfi::st
