// Whole-number command-line options with their range checked while the options are parsed:
// Boost's own conversion reads "-1" for an unsigned option as 2^64-1, so `--cycles -1` ran
// for ever. Use po::value<Count>() or po::value<IntIn<lo, hi>>() instead of the bare types.
#pragma once

#include <cstdint>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <boost/any.hpp>
#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "build.hpp"
#include "codegen/compiler.hpp"
#include "import/import.hpp"

namespace plcfi::cli {

// Decimal digits with an optional sign, no spaces: the sign and the magnitude. False when
// the text is not such a number or the magnitude exceeds 2^64-1.
inline bool parse_whole(const std::string& text, bool* negative, uint64_t* magnitude) {
  size_t i = 0;
  *negative = false;
  if (i < text.size() && (text[i] == '-' || text[i] == '+')) *negative = text[i++] == '-';
  if (i == text.size()) return false;
  uint64_t v = 0;
  for (; i < text.size(); ++i) {
    char c = text[i];
    if (c < '0' || c > '9') return false;
    unsigned d = static_cast<unsigned>(c - '0');
    if (v > (std::numeric_limits<uint64_t>::max() - d) / 10) return false;
    v = v * 10 + d;
  }
  *magnitude = v;
  return true;
}

// The error names the option (Boost fills it in) and the range expected.
class OutOfRangeError : public boost::program_options::error_with_option_name {
 public:
  OutOfRangeError(const std::string& token, const std::string& expected)
      : error_with_option_name("option '%canonical_option%': '%value%' is not " + expected, "", token) {
    set_substitute("value", token);
  }
};

// A count of cycles, iterations, ...: 0 up to 2^64-1.
struct Count {
  uint64_t value = 0;
};

inline void validate(boost::any& out, const std::vector<std::string>& values, Count*, int) {
  boost::program_options::validators::check_first_occurrence(out);
  const std::string& s = boost::program_options::validators::get_single_string(values);
  bool neg = false;
  uint64_t v = 0;
  if (!parse_whole(s, &neg, &v) || (neg && v != 0))
    throw OutOfRangeError(s, fmt::format("a whole number from 0 to {}", std::numeric_limits<uint64_t>::max()));
  out = Count{v};
}

// A small signed setting with a fixed range (a priority, a CPU number).
template <int64_t Lo, int64_t Hi>
struct IntIn {
  static_assert(Lo <= Hi);
  int64_t value = Lo;
};

template <int64_t Lo, int64_t Hi>
void validate(boost::any& out, const std::vector<std::string>& values, IntIn<Lo, Hi>*, int) {
  boost::program_options::validators::check_first_occurrence(out);
  const std::string& s = boost::program_options::validators::get_single_string(values);
  bool neg = false;
  uint64_t v = 0;
  // Lo and Hi are small: a magnitude past 2^62 is out of range whatever its sign.
  bool ok = parse_whole(s, &neg, &v) && v < (uint64_t{1} << 62);
  int64_t x = ok ? (neg ? -static_cast<int64_t>(v) : static_cast<int64_t>(v)) : 0;
  if (!ok || x < Lo || x > Hi) throw OutOfRangeError(s, fmt::format("a whole number from {} to {}", Lo, Hi));
  out = IntIn<Lo, Hi>{x};
}

using RtPriority = IntIn<0, 99>;  // SCHED_FIFO priority; 0 keeps the normal scheduler
using CpuIndex = IntIn<-1, 1023>;  // CPU affinity; -1 leaves the thread on any CPU

// Parses a subcommand's arguments: its options, and plain arguments collected under the
// name `positional` (none when null). --help prints the usage line and the options and
// returns false; errors throw boost::program_options::error, reported by main.
inline bool parse_args(const std::vector<std::string>& args, boost::program_options::options_description& desc,
                       boost::program_options::variables_map& vm, const std::string& usage,
                       const char* positional = "files") {
  namespace po = boost::program_options;
  desc.add_options()("help,h", "show this help");
  po::options_description all;
  all.add(desc);
  po::positional_options_description pos;
  if (positional) {
    all.add_options()(positional, po::value<std::vector<std::string>>(), "");
    pos.add(positional, -1);
  }
  po::store(po::command_line_parser(args).options(all).positional(pos).run(), vm);
  po::notify(vm);
  if (vm.count("help")) {
    std::cout << "usage: " << usage << "\n\n" << desc << "\n";
    return false;
  }
  return true;
}

// --dialect, --strict and --library, on every command that reads ST.
inline void add_dialect_options(boost::program_options::options_description& desc) {
  desc.add_options()
      ("dialect", boost::program_options::value<std::string>()->default_value("iec"),
       "ST dialect: iec (IEC 61131-3) or codesys (CODESYS and TwinCAT 3: implicit conversions as warnings, ...)")
      ("strict", "with --dialect codesys: the dialect's implicit conversions are errors")
      ("library", boost::program_options::value<std::vector<std::string>>()->value_name("DIR"),
       "a library as sources: the .plcproj under DIR, else every .st, TwinCAT object (.TcPOU, ...) and "
       "PLCopen .xml under it; its POUs, types and globals are the program's to use (repeatable)");
}
// The dialect and library options into `opt`; a dialect that does not exist, or a
// library folder that does not exist or holds no sources, is a usage error.
// Without --dialect, TwinCAT project files (the program's or a library's) are read as
// what they are: CODESYS ST.
inline void apply_dialect_options(const boost::program_options::variables_map& vm, st::CompileOptions* opt) {
  const std::string& d = vm["dialect"].as<std::string>();
  if (!st::parse_dialect(d, &opt->dialect))
    throw boost::program_options::error("--dialect must be iec or codesys, not '" + d + "'");
  if (vm.count("library"))
    for (const auto& dir : vm["library"].as<std::vector<std::string>>()) {
      std::string err;
      if (!st::library_sources(dir, &opt->library_files, &err)) throw boost::program_options::error(err);
    }
  std::vector<std::string> inputs = opt->library_files;
  if (vm.count("files"))
    for (const auto& f : vm["files"].as<std::vector<std::string>>()) inputs.push_back(f);
  if (vm["dialect"].defaulted())
    for (const auto& f : inputs)
      if (st::input_kind(f) == st::InputKind::TwinCat) opt->dialect = st::Dialect::Codesys;
  opt->strict = vm.count("strict") != 0;
}

// The values of a repeatable string option or of the plain arguments; empty when absent.
inline std::vector<std::string> strings_of(const boost::program_options::variables_map& vm, const char* key) {
  return vm.count(key) ? vm[key].as<std::vector<std::string>>() : std::vector<std::string>{};
}

// The program (with `late`: monitors, preconditions) compiled with the dialect and library
// options and without warnings, its diagnostics on stderr. Null when it does not compile.
inline std::unique_ptr<st::Build> compile_program(const boost::program_options::variables_map& vm,
                                                  const std::vector<std::string>& files, const st::GeneratedSources& late = {}) {
  st::CompileOptions opt;
  apply_dialect_options(vm, &opt);
  opt.warnings = false;
  auto b = st::build_files(files, opt, late);
  for (const auto& e : b->io_errors) std::cerr << e << "\n";
  std::cerr << b->diags.render_all();
  if (!b->ok()) return nullptr;
  return b;
}

}  // namespace plcfi::cli
