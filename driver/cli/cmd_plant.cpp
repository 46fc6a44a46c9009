// `plcfi plant`: look at a plant (its signals and where they sit in the image) and export the
// built-in stamping plant as an FMI 2.0 co-simulation FMU.
#include <unistd.h>

#include <filesystem>
#include <iostream>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "commands.hpp"
#include "common/duration.hpp"
#include "common/yaml.hpp"
#include "io/sim/plant_factory.hpp"
#include "options.hpp"
#include "plant_model/fmu/export.hpp"
#include "plant_model/fmu/export/stamping_fmu.hpp"
#include "plant_model/plant.hpp"
#include "runtime/schedule.hpp"

namespace po = boost::program_options;

namespace plcfi::cli {

std::string exe_dir() {
  std::error_code ec;
  auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string(".") : p.parent_path().string();
}

namespace {

int plant_info(const std::vector<std::string>& args) {
  po::options_description desc("plcfi plant info: the signals of a plant and their image addresses");
  desc.add_options()("plant-config", po::value<std::string>(), "parameters of a built-in plant (YAML)");
  po::variables_map vm;
  if (!parse_args(args, desc, vm, "plcfi plant info PLANT (a built-in plant's name, or a plant file)", "plants")) return 0;
  if (!vm.count("plants") || vm["plants"].as<std::vector<std::string>>().size() != 1) {
    std::cerr << "plcfi plant info: name one plant (stamping, bead_dispenser or a plant file)\n";
    return 2;
  }
  const std::string name = vm["plants"].as<std::vector<std::string>>().front();
  std::string err;
  auto plant = io::open_plant(name, vm.count("plant-config") ? vm["plant-config"].as<std::string>() : "", &err);
  if (!plant) {
    std::cerr << "plcfi plant info: " << err << "\n";
    return 2;
  }
  std::cout << fmt::format("plant {}{}\n", plant->name(), plant->origin().empty() ? " (built-in)" : ": " + plant->origin());
  std::cout << (plant->step_ns() > 0 ? fmt::format("  step {}\n", common::format_duration(plant->step_ns()))
                                     : std::string("  step: with every scan, by the base tick\n"));
  for (const auto& n : plant->notes()) std::cout << "  note: " << n << "\n";
  size_t width = 4;
  for (const auto& s : plant->signals()) width = std::max(width, s.name.size());
  std::cout << fmt::format("  {:<8} {:<{}} {:<9} {:<7} {}\n", "image", "signal", width, "direction", "kind", "description");
  for (const auto& s : plant->signals())
    std::cout << fmt::format("  {:<8} {:<{}} {:<9} {:<7} {}\n", s.address, s.name, width,
                             s.dir == plant::Direction::FromPlant ? "sensor" : "actuator",
                             s.kind == plant::SignalKind::Bool ? "BOOL" : "analog", s.description);
  return 0;
}

int plant_export_fmu(const std::vector<std::string>& args) {
  po::options_description desc("plcfi plant export-fmu: pack the built-in stamping plant as an FMI 2.0 co-simulation FMU");
  desc.add_options()
      ("plant", po::value<std::string>()->default_value("stamping"), "the built-in plant (stamping)")
      ("output,o", po::value<std::string>(), "the .fmu file to write")
      ("plant-file", po::value<std::string>(), "also write a plant file (YAML) that maps the FMU onto the image "
                                               "addresses of the built-in plant")
      ("step", po::value<std::string>()->default_value("10ms"), "the step of the plant file and the FMU's "
                                                                 "DefaultExperiment");
  po::variables_map vm;
  if (!parse_args(args, desc, vm, "plcfi plant export-fmu [--plant stamping] -o stamping.fmu [--plant-file stamping_fmu.yaml]",
                  nullptr))
    return 0;
  if (vm["plant"].as<std::string>() != "stamping") {
    std::cerr << "plcfi plant export-fmu: --plant: only the built-in stamping plant can be exported, not '"
              << vm["plant"].as<std::string>() << "'\n";
    return 2;
  }
  if (!vm.count("output")) {
    std::cerr << "plcfi plant export-fmu: -o FILE.fmu is required\n";
    return 2;
  }
  plant::fmu::ExportOptions opt;
  opt.out = vm["output"].as<std::string>();
  if (vm.count("plant-file")) opt.plant_file = vm["plant-file"].as<std::string>();
  std::string err;
  if (!rt::parse_duration(vm["step"].as<std::string>(), &opt.step_ns, &err) || opt.step_ns <= 0) {
    std::cerr << "plcfi plant export-fmu: --step: " << (err.empty() ? "must be positive" : err) << "\n";
    return 2;
  }
  opt.library = exe_dir() + "/" + plant::fmu::kStampingFmuLibrary;
  auto plant = plant::make_builtin_plant("stamping", "", &err);
  try {
    plant::fmu::export_stamping_fmu(*plant, opt);
  } catch (const common::InputError& e) {
    std::cerr << "plcfi plant export-fmu: " << e.what() << "\n";
    return 2;
  }
  std::cout << fmt::format("plcfi plant export-fmu: wrote {} (FMI 2.0 co-simulation, model {}, {} variables, step {})\n",
                           opt.out, plant->name(), plant->signals().size() + 1, common::format_duration(opt.step_ns));
  if (!opt.plant_file.empty()) std::cout << fmt::format("  and the plant file {}\n", opt.plant_file);
  return 0;
}

}  // namespace

int cmd_plant(const std::vector<std::string>& args) {
  const std::string sub = args.empty() ? "" : args.front();
  const std::vector<std::string> rest(args.empty() ? args.end() : args.begin() + 1, args.end());
  if (sub == "info") return plant_info(rest);
  if (sub == "export-fmu") return plant_export_fmu(rest);
  std::ostream& os = sub == "--help" || sub == "-h" ? std::cout : std::cerr;
  if (!sub.empty() && sub != "--help" && sub != "-h") os << "plcfi plant: unknown subcommand '" << sub << "'\n\n";
  os << "usage: plcfi plant info PLANT\n"
        "       plcfi plant export-fmu [--plant stamping] -o FILE.fmu [--plant-file FILE.yaml] [--step 10ms]\n\n"
        "  info        the signals of a plant (built-in, or a plant file: FMU or ST) and their image addresses\n"
        "  export-fmu  pack the built-in stamping plant as an FMI 2.0 co-simulation FMU\n";
  return sub == "--help" || sub == "-h" ? 0 : 2;
}

}  // namespace plcfi::cli
