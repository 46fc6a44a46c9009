// The plcfi executable: subcommand dispatch and option parsing. Each command is thin and
// delegates to the libraries. Exit status: 0 success, 1 a test or check failed,
// 2 bad usage or input.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <boost/program_options.hpp>

#include "commands.hpp"

namespace po = boost::program_options;

namespace {

struct Command {
  const char* name;
  const char* summary;
  int (*run)(const std::vector<std::string>& args);
};

const std::vector<Command>& commands() {
  static const std::vector<Command> k = {
      {"check", "compile ST files and print diagnostics", plcfi::cli::cmd_check},
      {"run", "run ST programs in virtual time and print variables, or on real I/O in real time", plcfi::cli::cmd_run},
      {"test", "run ST unit-test files", plcfi::cli::cmd_test},
      {"disasm", "print the bytecode of ST files with their source lines", plcfi::cli::cmd_disasm},
      {"sim", "run a PLC program on a plant model in virtual time", plcfi::cli::cmd_sim},
      {"edtl", "check EDTL requirements on a recorded trace (edtl check REQS TRACE)", plcfi::cli::cmd_edtl},
      {"generate", "generate the prioritized fault-injection test cases of a campaign (TSD + FMEA)", plcfi::cli::cmd_generate},
      {"campaign", "run a passive fault-injection campaign on the plant model or, armed, on real I/O", plcfi::cli::cmd_campaign},
      {"mutate", "mutation analysis of the program's error handling: mutants of the compiled program judged by a campaign", plcfi::cli::cmd_mutate},
      {"script", "run CPTest+ test scripts (.cpt) against a program and a plant model, with ASSERT_COM and link faults", plcfi::cli::cmd_script},
      {"history", "show the run history of test scripts, newest first", plcfi::cli::cmd_history},
      {"plant", "look at a plant's signals (plant info) or export the stamping plant as an FMU (plant export-fmu)", plcfi::cli::cmd_plant},
      {"export-fmu", "pack the PLC program as an FMI 2.0 co-simulation FMU, with fault parameters on its I/O", plcfi::cli::cmd_export_fmu},
      {"merge", "combine the shard files of campaign --shard or mutate --shard into the journal of one run", plcfi::cli::cmd_merge},
      {"plant-server", "serve a plant model in real time over Modbus TCP (bench rehearsal)", plcfi::cli::cmd_plant_server},
  };
  return k;
}

void usage(std::ostream& os) {
  os << "usage: plcfi <command> [options] [files...]\n\n"
        "plcfi tests IEC 61131-3 Structured Text programs under faults.\n\ncommands:\n";
  size_t width = 0;
  for (const auto& c : commands()) width = std::max(width, std::string(c.name).size());
  for (const auto& c : commands())
    os << "  " << c.name << std::string(width + 2 - std::string(c.name).size(), ' ') << c.summary << "\n";
  os << "\n'plcfi <command> --help' describes a command's options.\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    usage(std::cerr);
    return 2;
  }
  std::string cmd = argv[1];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    usage(std::cout);
    return 0;
  }
  if (cmd == "--version") {
    std::cout << "plcfi 0.1.0\n";
    return 0;
  }
  std::vector<std::string> args(argv + 2, argv + argc);
  for (const auto& c : commands())
    if (cmd == c.name) {
      try {
        return c.run(args);
      } catch (const po::error& e) {
        std::cerr << "plcfi " << cmd << ": " << e.what() << "\n(see 'plcfi " << cmd << " --help')\n";
        return 2;
      } catch (const std::exception& e) {
        std::cerr << "plcfi " << cmd << ": " << e.what() << "\n";
        return 2;
      }
    }
  std::cerr << "plcfi: unknown command '" << cmd << "'\n\n";
  usage(std::cerr);
  return 2;
}
