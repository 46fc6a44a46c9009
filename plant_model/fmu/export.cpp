// FMU export of the built-in stamping plant (libzip writes the archive).
#include "plant_model/fmu/export.hpp"

#include <zip.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "common/duration.hpp"
#include "common/yaml.hpp"
#include "plant_model/fmu/export/stamping_fmu.hpp"

namespace plcfi::plant::fmu {

namespace {

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

void write_fmu_archive(const std::string& out, const std::vector<ArchiveEntry>& entries) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const std::string tmp = out + ".tmp";
  fs::remove(tmp, ec);
  int zerr = 0;
  zip_t* z = zip_open(tmp.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &zerr);
  if (!z) {
    zip_error_t e;
    zip_error_init_with_code(&e, zerr);
    std::string what = zip_error_strerror(&e);
    zip_error_fini(&e);
    throw common::InputError(fmt::format("{}: cannot write: {}", out, what));
  }
  auto fail = [&](const std::string& what) {
    std::string msg = fmt::format("{}: cannot write: {}: {}", out, what, zip_error_strerror(zip_get_error(z)));
    zip_discard(z);
    fs::remove(tmp, ec);
    throw common::InputError(msg);
  };
  for (const auto& e : entries) {
    // zip_source_buffer keeps a pointer: `entries` outlives zip_close below.
    zip_source_t* src = e.from.empty() ? zip_source_buffer(z, e.data.data(), e.data.size(), 0)
                                       : zip_source_file(z, e.from.c_str(), 0, -1);
    if (!src || zip_file_add(z, e.name.c_str(), src, ZIP_FL_ENC_UTF_8) < 0) {
      if (src) zip_source_free(src);
      fail(e.name);
    }
  }
  if (zip_close(z) != 0) fail("closing the archive");
  fs::rename(tmp, out, ec);
  if (ec) throw common::InputError(fmt::format("{}: cannot write: {}", out, ec.message()));
}

std::string stamping_model_description(const Plant& plant, int64_t step_ns) {
  const auto& sigs = plant.signals();
  std::string vars, outputs;
  size_t index = 0;  // 1-based position of a ScalarVariable, for ModelStructure
  for (size_t i = 0; i < sigs.size(); ++i) {
    const SignalInfo& s = sigs[i];
    const bool out = s.dir == Direction::FromPlant;
    const bool b = s.kind == SignalKind::Bool;
    ++index;
    vars += fmt::format(
        "    <ScalarVariable name=\"{}\" valueReference=\"{}\" description=\"{}\" causality=\"{}\" "
        "variability=\"discrete\"{}>\n      <{}{}/>\n    </ScalarVariable>\n",
        xml_escape(s.name), i, xml_escape(s.description), out ? "output" : "input",
        out ? " initial=\"calculated\"" : "", b ? "Boolean" : "Integer", out ? "" : b ? " start=\"false\"" : " start=\"0\"");
    if (out) outputs += fmt::format("      <Unknown index=\"{}\"/>\n", index);
  }
  vars += fmt::format(
      "    <ScalarVariable name=\"seed\" valueReference=\"{}\" description=\"seed of the random variation of the "
      "travel times\" causality=\"parameter\" variability=\"fixed\">\n      <Integer start=\"1\"/>\n    "
      "</ScalarVariable>\n",
      kStampingFmuSeedRef);
  const auto stats = plant.stats();
  for (size_t k = 0; k < stats.size(); ++k)
    vars += fmt::format(
        "    <ScalarVariable name=\"{}\" valueReference=\"{}\" description=\"statistics of the run\" "
        "causality=\"local\" variability=\"discrete\" initial=\"calculated\">\n      <Integer/>\n    </ScalarVariable>\n",
        xml_escape(stats[k].first), kStampingFmuStatsRef + k);
  return fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{name}\" guid=\"{guid}\"\n"
      "  description=\"The stamping module of plcfi (slider, stamp cylinder, pressure, workpieces, operator), "
      "exported by plcfi plant export-fmu\"\n"
      "  generationTool=\"plcfi\" variableNamingConvention=\"flat\" numberOfEventIndicators=\"0\">\n"
      "  <CoSimulation modelIdentifier=\"{id}\" canHandleVariableCommunicationStepSize=\"true\" "
      "canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"false\" providesDirectionalDerivative=\"false\"/>\n"
      "  <DefaultExperiment startTime=\"0\" stepSize=\"{step}\"/>\n"
      "  <ModelVariables>\n{vars}  </ModelVariables>\n"
      "  <ModelStructure>\n    <Outputs>\n{outs}    </Outputs>\n    <InitialUnknowns>\n{outs}    </InitialUnknowns>\n"
      "  </ModelStructure>\n"
      "</fmiModelDescription>\n",
      fmt::arg("name", plant.name()), fmt::arg("guid", kStampingFmuGuid), fmt::arg("id", kStampingFmuIdentifier),
      fmt::arg("step", static_cast<double>(step_ns) * 1e-9), fmt::arg("vars", vars), fmt::arg("outs", outputs));
}

void export_stamping_fmu(const Plant& plant, const ExportOptions& opt) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_regular_file(opt.library, ec))
    throw common::InputError(fmt::format("{}: the FMU binary is missing (it is built with plcfi: target plcfi_stamping_fmu)",
                                         opt.library));
  write_fmu_archive(opt.out, {{"modelDescription.xml", stamping_model_description(plant, opt.step_ns), ""},
                              {fmt::format("binaries/linux64/{}.so", kStampingFmuIdentifier), "", opt.library}});

  if (opt.plant_file.empty()) return;
  std::string stat_names;
  for (const auto& [name, value] : plant.stats()) stat_names += (stat_names.empty() ? "" : ", ") + name;
  // The FMU path relative to the plant file, so the two can move together.
  fs::path rel = fs::absolute(opt.out).lexically_relative(fs::absolute(opt.plant_file).parent_path());
  std::string text = fmt::format(
      "# The stamping module as an FMU, mapped onto the image addresses of the built-in plant\n"
      "# (written by plcfi plant export-fmu).\n"
      "fmu: {}\n"
      "step: {}\n"
      "seed_parameter: seed   # the run's seed goes to this Integer parameter at every restart\n"
      "stats: [{}]\n"
      "map:\n",
      rel.empty() ? opt.out : rel.string(), common::format_duration(opt.step_ns), stat_names);
  for (const auto& s : plant.signals())
    text += fmt::format("  - {{image: \"{}\", plant: {}}}\n", s.address, s.name);
  std::ofstream f(opt.plant_file, std::ios::binary | std::ios::trunc);
  f << text;
  f.close();
  if (!f) throw common::InputError(fmt::format("{}: cannot write", opt.plant_file));
}

}  // namespace plcfi::plant::fmu
