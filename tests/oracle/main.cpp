// plcfi_oracle: differential testing of the ST engine (interpreter and native tier) against
// the reference evaluator, on random programs from the generator or on given files.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "engine.hpp"
#include "generator.hpp"
#include "native/native.hpp"
#include "reference.hpp"
#include "syntax/parser.hpp"

namespace plcfi::oracle {
namespace {

struct Options {
  uint64_t seed = 1;
  uint64_t count = 100;
  int scans = 5;
  uint64_t native_every = 0;  // 0: never; n: every n-th program also runs natively
  std::string out = "oracle-out";
  std::vector<std::string> files;
  GenOptions gen;
  uint64_t shrink_first = 1;  // failures shrunk (each costs up to thousands of runs)
  bool verbose = false;
  bool self_check = false;
};

enum class Kind { Match, Mismatch, CompileError, Unsupported, RefTrap, EngineTrap, NativeError };
const char* kind_name(Kind k) {
  switch (k) {
    case Kind::Match: return "match";
    case Kind::Mismatch: return "MISMATCH";
    case Kind::CompileError: return "engine compile error";
    case Kind::Unsupported: return "outside the evaluator's subset";
    case Kind::RefTrap: return "reference trapped";
    case Kind::EngineTrap: return "engine trapped";
    case Kind::NativeError: return "native build failed";
  }
  return "?";
}

struct Outcome {
  Kind kind = Kind::Match;
  std::string detail;
};

// Equal values: integers by their bits, reals by value (so -0.0 equals 0.0, which MIN and
// MAX may return either of), NaN equal to NaN, strings by their text.
bool same(const st::Machine& m, const st::VarHandle& h, const Value& v, std::string* engine_text) {
  *engine_text = st::format(m, h);
  switch (v.t->kind) {
    case VK::Bool: return st::read_bool(m, h) == (v.i != 0);
    case VK::Int:
    case VK::Time:
    case VK::Date: {
      uint64_t mask = v.t->bits == 64 || v.t->kind != VK::Int ? ~uint64_t{0} : (uint64_t{1} << v.t->bits) - 1;
      return (static_cast<uint64_t>(st::read_int(m, h)) & mask) == (static_cast<uint64_t>(v.i) & mask);
    }
    case VK::Real:
    case VK::LReal: {
      double x = st::read_real(m, h);
      return x == v.r || (x != x && v.r != v.r);
    }
    case VK::String: return *engine_text == "'" + v.s + "'";
    default: return true;
  }
}

// Compiles and runs one program in the interpreter (and natively when asked) and in the
// reference evaluator, comparing every variable after every scan.
// The dialect every program is compiled and evaluated in (--dialect).
bool g_codesys = false;

Outcome check(const std::string& name, const std::string& text, int scans, bool native, bool wrong_reference = false) {
  st::CompileOptions copt;
  copt.warnings = false;
  if (g_codesys) copt.dialect = st::Dialect::Codesys;
  auto b = st::build_sources({{name, text}}, copt);
  if (!b->ok()) return {Kind::CompileError, b->diags.render_all()};
  const st::Application& app = *b->app;

  st::SourceManager sm;
  st::DiagEngine diags(sm);
  auto unit = st::parse_unit(sm, sm.add(name, text), diags);
  std::unique_ptr<Reference> ref;
  try {
    ref = std::make_unique<Reference>(std::vector<const st::CompilationUnit*>{unit.get()});
    ref->set_wrong_addition(wrong_reference);
    ref->set_codesys(g_codesys);
  } catch (const Unsupported& e) {
    return {Kind::Unsupported, e.what()};
  } catch (const RefTrap& e) {
    return {Kind::RefTrap, std::string("initial values: ") + e.what()};
  }

  std::unique_ptr<st::NativeCode> code;
  if (native) {
    std::string err;
    code = st::NativeCode::build(app, st::NativeOptions{}, &err);
    if (!code) return {Kind::NativeError, err};
  }
  Outcome result;
  {
    st::Machine interp(app);
    std::optional<st::Machine> nat;
    interp.set_budget(10'000'000);
    if (code) {
      nat.emplace(app);
      nat->set_budget(10'000'000);
      nat->set_native(code.get());
    }
    std::map<std::string, st::VarHandle> handles;
    const auto scratch = st::scratch_ranges(app);
    for (int s = 0; s < scans && result.kind == Kind::Match; ++s) {
      std::vector<st::Machine*> machines{&interp};
      if (nat) machines.push_back(&*nat);
      for (st::Machine* m : machines) {
        m->set_now(s * 10'000'000LL);
        for (const auto& inst : app.programs)
          if (!m->call(inst.pou->entry, inst.addr)) {
            result = {Kind::EngineTrap, "scan " + std::to_string(s + 1) + (m == &interp ? " (interpreter): " : " (native): ") +
                                            st::describe_trap(app, m->trap())};
            break;
          }
      }
      if (result.kind != Kind::Match) break;
      // The two tiers must also agree on what the reference does not compare (FOR control
      // variables, interface and reference slots, padding): the whole memory but the
      // compiler's temporaries, whose dead stores the native tier leaves out.
      if (nat && st::first_difference(scratch, interp.mem(), nat->mem(), interp.mem_size()) != interp.mem_size()) {
        result = {Kind::Mismatch, "after scan " + std::to_string(s + 1) + ": the interpreter's and the native tier's memory differ"};
        break;
      }
      try {
        ref->scan();
      } catch (const RefTrap& e) {
        result = {Kind::RefTrap, "scan " + std::to_string(s + 1) + ": " + e.what()};
        break;
      } catch (const Unsupported& e) {
        result = {Kind::Unsupported, e.what()};
        break;
      }
      for (const Leaf& leaf : ref->leaves()) {
        auto it = handles.find(leaf.path);
        if (it == handles.end()) {
          std::string err;
          auto h = st::resolve(app, leaf.path, &err);
          if (!h) {
            result = {Kind::Unsupported, "the engine does not resolve " + leaf.path + ": " + err};
            break;
          }
          it = handles.emplace(leaf.path, *h).first;
        }
        std::string ti, tn;
        bool ok_i = same(interp, it->second, leaf.v, &ti);
        bool ok_n = !nat || same(*nat, it->second, leaf.v, &tn);
        if (!ok_i || !ok_n) {
          std::string d = "after scan " + std::to_string(s + 1) + ": " + leaf.path + " = " + Reference::text(leaf.v) +
                          " in the reference, " + ti + " in the interpreter";
          if (nat) d += ", " + tn + " in the native tier";
          result = {Kind::Mismatch, d};
          break;
        }
      }
    }
  }
  if (code) {
    std::error_code ec;
    std::filesystem::remove(code->library(), ec);  // long runs would fill the cache otherwise
  }
  return result;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

std::string join(const std::vector<std::string>& lines) {
  std::string t;
  for (const auto& l : lines) t += l + "\n";
  return t;
}

// What a shrunk program must keep: the same kind of failure, and for a trap the same
// message (a deleted assignment must not turn one trap into another).
bool same_failure(const Outcome& a, const Outcome& b) {
  if (a.kind != b.kind) return false;
  if (a.kind != Kind::EngineTrap) return true;
  auto msg = [](const std::string& d) {
    auto at = d.find("runtime error");
    return at == std::string::npos ? d : d.substr(at);
  };
  return msg(a.detail) == msg(b.detail);
}

// Deletes what it can while the failure stays: whole POUs, methods and properties, then
// statement lines (every statement is on a line of its own; declarations end in ';' too,
// and the compiler rejects a program that still needs one), until nothing more goes.
std::string shrink(const std::string& text, int scans, bool native, Outcome* failure) {
  std::vector<std::string> lines = split_lines(text);
  int tries = 0;
  const int max_tries = native ? 120 : 4000;
  auto attempt = [&](size_t from, size_t to) {  // deletes lines [from, to)
    if (tries >= max_tries) return false;
    std::vector<std::string> cand = lines;
    cand.erase(cand.begin() + static_cast<long>(from), cand.begin() + static_cast<long>(to));
    ++tries;
    Outcome o = check("shrink.st", join(cand), scans, native);
    if (!same_failure(o, *failure)) return false;
    lines = std::move(cand);
    *failure = o;
    return true;
  };
  static const char* kBlocks[][2] = {{"FUNCTION_BLOCK ", "END_FUNCTION_BLOCK"}, {"FUNCTION ", "END_FUNCTION"},
                                     {"METHOD ", "END_METHOD"},                 {"PROPERTY ", "END_PROPERTY"},
                                     {"VAR", "END_VAR"},                        {"SET", "END_SET"},
                                     {"GET", "END_GET"}};
  for (bool changed = true; changed && tries < max_tries;) {
    changed = false;
    // Keywords may be in any case (the generator scrambles some).
    auto upper = [](std::string t) {
      for (char& ch : t) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
      return t;
    };
    for (const auto& b : kBlocks) {
      for (size_t i = lines.size(); i-- > 0;) {
        if (i >= lines.size() || upper(lines[i]).rfind(b[0], 0) != 0) continue;
        if (std::string(b[0]) == "VAR" && lines[i].find(' ') != std::string::npos) continue;
        size_t j = i + 1;
        while (j < lines.size() && upper(lines[j]) != b[1] && upper(lines[j]).rfind(std::string(b[1]) + " ", 0) != 0) ++j;
        if (j < lines.size() && attempt(i, j + 1)) changed = true;
      }
    }
    for (size_t i = lines.size(); i-- > 0;) {
      if (i >= lines.size()) continue;
      const std::string& l = lines[i];
      if (l.empty() || l.back() != ';' || upper(l).rfind("END_", 0) == 0) continue;
      if (attempt(i, i + 1)) changed = true;
    }
    // Inside a compound statement's line: delete one `...;` piece at a time (a piece that
    // is not a whole statement leaves a program the compiler rejects, so it stays).
    for (size_t i = 0; i < lines.size() && tries < max_tries; ++i) {
      for (size_t end = lines[i].size(); end > 0 && tries < max_tries;) {
        size_t semi = lines[i].rfind(';', end - 1);
        if (semi == std::string::npos || semi == 0) break;
        size_t prev = lines[i].rfind(';', semi - 1);
        size_t from = prev == std::string::npos ? 0 : prev + 1;
        std::vector<std::string> cand = lines;
        cand[i].erase(from, semi + 1 - from);
        ++tries;
        Outcome o = check("shrink.st", join(cand), scans, native);
        if (same_failure(o, *failure)) {
          lines = std::move(cand);
          *failure = o;
          changed = true;
          end = std::min(from, lines[i].size());
        } else {
          end = from;
        }
      }
    }
  }
  return join(lines);
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  f << text;
}

int usage() {
  std::fprintf(stderr,
               "usage: plcfi_oracle [--seed S] [--count N] [--scans K] [--native | --no-native]\n"
               "                    [--native-every M] [--out DIR] [--avoid method-args-with-calls]\n"
               "                    [--shrink-first N | --no-shrink] [--verbose] [--dialect iec|codesys] [FILE.st ...]\n"
               "       plcfi_oracle --seed S [--avoid ...] --emit     (prints the program of seed S)\n"
               "       plcfi_oracle --self-check [--seed S --count N] (a wrong reference must be caught)\n"
               "Generates N programs from seeds S, S+1, ... (or takes the given files), runs K scans of each\n"
               "in the interpreter (and the native tier: --native every program, --native-every M every M-th)\n"
               "and in the reference evaluator, and compares every variable after every scan. Failing programs\n"
               "are written to DIR; the first N failures (default 1) are also shrunk to DIR/<name>.min.st.\n");
  return 2;
}

int run(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "plcfi_oracle: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    try {
      if (a == "--seed") o.seed = std::stoull(next());
      else if (a == "--count") o.count = std::stoull(next());
      else if (a == "--scans") o.scans = std::stoi(next());
      else if (a == "--native") o.native_every = 1;
      else if (a == "--no-native") o.native_every = 0;
      else if (a == "--native-every") o.native_every = std::stoull(next());
      else if (a == "--out") o.out = next();
      else if (a == "--no-shrink") o.shrink_first = 0;
      else if (a == "--shrink-first") o.shrink_first = std::stoull(next());
      else if (a == "--verbose") o.verbose = true;
      else if (a == "--dialect") {
        std::string d = next();
        if (d != "iec" && d != "codesys") {
          std::fprintf(stderr, "plcfi_oracle: --dialect must be iec or codesys, not '%s'\n", d.c_str());
          return 2;
        }
        g_codesys = d == "codesys";
      }
      else if (a == "--self-check") o.self_check = true;
      else if (a == "--emit") {  // prints the program of --seed and stops
        std::fputs(generate_program(o.seed, o.gen).c_str(), stdout);
        return 0;
      }
      else if (a == "--avoid") {
        std::string what = next();
        if (what != "method-args-with-calls") {
          std::fprintf(stderr, "plcfi_oracle: --avoid knows only method-args-with-calls, not '%s'\n", what.c_str());
          return 2;
        }
        o.gen.avoid_method_args_with_calls = true;
      } else if (a == "--help" || a == "-h") {
        usage();
        return 0;
      } else if (!a.empty() && a[0] == '-') {
        std::fprintf(stderr, "plcfi_oracle: unknown option '%s'\n", a.c_str());
        return usage();
      } else {
        o.files.push_back(a);
      }
    } catch (const std::exception&) {
      std::fprintf(stderr, "plcfi_oracle: bad value for %s\n", a.c_str());
      return 2;
    }
  }
  if (o.self_check) {
    // The comparison must catch a wrong reference: with integer additions off by one, most
    // programs must mismatch (a few may add no integers that reach a variable).
    uint64_t caught = 0;
    for (uint64_t k = 0; k < o.count; ++k) {
      std::string text = generate_program(o.seed + k, o.gen);
      caught += check("self-check.st", text, o.scans, false, true).kind == Kind::Mismatch;
    }
    std::printf("self-check: %llu of %llu programs caught with a wrong reference\n", static_cast<unsigned long long>(caught),
                static_cast<unsigned long long>(o.count));
    return caught * 10 >= o.count * 9 ? 0 : 1;
  }
  std::filesystem::create_directories(o.out);
  std::map<Kind, uint64_t> counts;
  uint64_t natives = 0, shrunk = 0;
  auto t0 = std::chrono::steady_clock::now();
  auto report = [&](const std::string& label, const std::string& text, bool native, const Outcome& r) {
    ++counts[r.kind];
    if (r.kind == Kind::Match) {
      if (o.verbose) std::printf("%s: match%s\n", label.c_str(), native ? " (with the native tier)" : "");
      return;
    }
    std::string file = o.out + "/" + label + ".st";
    write_file(file, text);
    std::printf("%s: %s%s\n  %s\n  program: %s\n", label.c_str(), kind_name(r.kind), native ? " (native tier on)" : "",
                r.detail.c_str(), file.c_str());
    if ((r.kind == Kind::Mismatch || r.kind == Kind::EngineTrap) && shrunk < o.shrink_first) {
      ++shrunk;
      Outcome failure = r;
      // A failure the interpreter shows alone shrinks without a native build per attempt.
      bool shrink_native = native && !same_failure(check(label + ".st", text, o.scans, false), r);
      std::string small = shrink(text, o.scans, shrink_native, &failure);
      std::string min_file = o.out + "/" + label + ".min.st";
      write_file(min_file, small);
      std::printf("  shrunk to %zu lines: %s\n  %s\n", split_lines(small).size(), min_file.c_str(), failure.detail.c_str());
    }
    std::fflush(stdout);
  };
  if (!o.files.empty()) {
    for (size_t k = 0; k < o.files.size(); ++k) {
      std::ifstream f(o.files[k]);
      if (!f) {
        std::fprintf(stderr, "plcfi_oracle: %s: cannot open\n", o.files[k].c_str());
        return 2;
      }
      std::stringstream ss;
      ss << f.rdbuf();
      bool native = o.native_every != 0;
      natives += native;
      Outcome r = check(o.files[k], ss.str(), o.scans, native);
      report(std::filesystem::path(o.files[k]).stem().string(), ss.str(), native, r);
      if (r.kind == Kind::Match) std::printf("%s: match\n", o.files[k].c_str());
    }
  } else {
    for (uint64_t k = 0; k < o.count; ++k) {
      uint64_t seed = o.seed + k;
      std::string text = generate_program(seed, o.gen);
      bool native = o.native_every != 0 && k % o.native_every == 0;
      natives += native;
      Outcome r = check("seed-" + std::to_string(seed) + ".st", text, o.scans, native);
      report("seed-" + std::to_string(seed), text, native, r);
    }
  }
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  uint64_t total = 0;
  for (const auto& [k, n] : counts) total += n;
  std::printf("%llu program(s), %llu with the native tier, %d scan(s) each, %.1f s (%.1f programs/s):",
              static_cast<unsigned long long>(total), static_cast<unsigned long long>(natives), o.scans, secs,
              secs > 0 ? static_cast<double>(total) / secs : 0.0);
  for (const auto& [k, n] : counts) std::printf(" %llu %s,", static_cast<unsigned long long>(n), kind_name(k));
  std::printf("\n");
  return counts[Kind::Match] == total ? 0 : 1;
}

}  // namespace
}  // namespace plcfi::oracle

int main(int argc, char** argv) { return plcfi::oracle::run(argc, argv); }
