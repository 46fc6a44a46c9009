// `plcfi export-fmu`: the PLC program under test as an FMI 2.0 co-simulation FMU.
#include <iostream>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "commands.hpp"
#include "common/duration.hpp"
#include "common/yaml.hpp"
#include "engine.hpp"
#include "fmu/export.hpp"
#include "options.hpp"

namespace po = boost::program_options;

namespace plcfi::cli {

int cmd_export_fmu(const std::vector<std::string>& args) {
  po::options_description desc(
      "plcfi export-fmu: pack the PLC program as an FMI 2.0 co-simulation FMU. Variables at %I addresses are its "
      "inputs, at %Q its outputs, named by path; each fmi2DoStep runs the program's tasks at its own cycle; String "
      "parameters fault.PATH (and Real fault_at.PATH, s) inject plcfi's fault models");
  desc.add_options()
      ("output,o", po::value<std::string>(), "the .fmu file to write")
      ("program", po::value<std::string>(), "run this program instance or type alone (default: the CONFIGURATION's "
                                            "tasks, or the only PROGRAM)")
      ("cycle-time", po::value<std::string>()->default_value("10ms"), "cycle time without a CONFIGURATION "
                                                                       "(or with --program)")
      ("model-identifier", po::value<std::string>(), "the FMU's model identifier (default: the output file's name)");
  add_dialect_options(desc);
  po::variables_map vm;
  if (!parse_args(args, desc, vm, "plcfi export-fmu PROGRAM.st... -o FILE.fmu [--dialect D] [--program NAME]")) return 0;
  fmu::ExportOptions opt;
  opt.sources = strings_of(vm, "files");
  if (opt.sources.empty()) {
    std::cerr << "plcfi export-fmu: no program files\n";
    return 2;
  }
  if (!vm.count("output")) {
    std::cerr << "plcfi export-fmu: -o FILE.fmu is required\n";
    return 2;
  }
  opt.out = vm["output"].as<std::string>();
  if (vm.count("program")) opt.program = vm["program"].as<std::string>();
  if (vm.count("model-identifier")) opt.model_identifier = vm["model-identifier"].as<std::string>();
  std::string err;
  if (!rt::parse_duration(vm["cycle-time"].as<std::string>(), &opt.cycle_ns, &err) || opt.cycle_ns <= 0) {
    std::cerr << "plcfi export-fmu: --cycle-time: " << (err.empty() ? "must be positive" : err) << "\n";
    return 2;
  }
  st::CompileOptions copt;
  apply_dialect_options(vm, &copt);
  copt.warnings = false;
  auto b = st::build_files(opt.sources, copt);
  for (const auto& e : b->io_errors) std::cerr << e << "\n";
  std::cerr << b->diags.render_all();
  if (!b->ok()) return 2;
  opt.libraries = copt.library_files;
  opt.dialect = copt.dialect;
  opt.strict = copt.strict;
  opt.binary = exe_dir() + "/plcfi_program_fmu.so";
  fmu::Manifest m;
  try {
    m = fmu::make_manifest(*b->app, opt);
    fmu::write_program_fmu(m, opt);
  } catch (const common::InputError& e) {
    std::cerr << "plcfi export-fmu: " << e.what() << "\n";
    return 2;
  }
  size_t inputs = 0;
  for (const auto& p : m.ports) inputs += p.input ? 1 : 0;
  std::cout << fmt::format(
      "plcfi export-fmu: wrote {} (FMI 2.0 co-simulation, model {}, {} inputs, {} outputs, {} fault parameters, "
      "base tick {})\n",
      opt.out, m.model_identifier, inputs, m.ports.size() - inputs, m.ports.size() * 2 + 1,
      common::format_duration(m.tick_ns));
  for (const auto& p : m.ports)
    std::cout << fmt::format("  {:<6} {:<8} {:<8} {:<7} {}\n", p.input ? "input" : "output", p.address, p.type,
                             fmu::fmi_type_name(p.fmi), p.path);
  return 0;
}

}  // namespace plcfi::cli
