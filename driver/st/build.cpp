// Building an application from files or in-memory sources (build.hpp).
#include "build.hpp"

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
#include "vm/cpp_functions.hpp"

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

}  // namespace plcfi::st
