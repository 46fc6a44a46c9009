// `plcfi export-fmu`: the manifest, modelDescription.xml and the archive of a program FMU.
#include "fmu/export.hpp"

#include <filesystem>

#include <fmt/format.h>

#include "common/file.hpp"
#include "common/hash.hpp"
#include "common/yaml.hpp"
#include "import/import.hpp"
#include "plant_model/fmu/export.hpp"
#include "report/junit.hpp"

namespace plcfi::fmu {

namespace {

namespace fs = std::filesystem;
using report::xml_escape;

constexpr size_t kMaxSource = 32u << 20;

std::string c_identifier(const std::string& s) {
  std::string id;
  for (char c : s) id += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_';
  if (id.empty()) id = "plc_program";
  if (std::isdigit(static_cast<unsigned char>(id[0]))) id = "_" + id;
  return id;
}

// "src/003_stamping.st": numbered, so files of the same name in two folders stay apart.
std::string archived_name(const char* folder, size_t i, const std::string& path) {
  return fmt::format("{}/{:03}_{}", folder, i, fs::path(path).filename().string());
}

std::string read_source(const std::string& path) {
  std::string text, err;
  if (!common::read_file(path, kMaxSource, &text, &err)) throw common::InputError(err);
  return text;
}

std::string number(double v) { return fmt::format("{}", v); }

}  // namespace

Manifest make_manifest(const st::Application& app, const ExportOptions& opt) {
  for (const auto* list : {&opt.sources, &opt.libraries})
    for (const auto& f : *list)
      if (fs::path(f).extension() == ".plcproj")
        throw common::InputError(
            f + ": a TwinCAT project file cannot be packed into an FMU; give its objects (.TcPOU, .TcGVL, .TcDUT, ...) "
                "as files");
  Manifest m;
  m.model_identifier = opt.model_identifier.empty() ? c_identifier(fs::path(opt.out).stem().string()) : opt.model_identifier;
  if (m.model_identifier != c_identifier(m.model_identifier))
    throw common::InputError("--model-identifier '" + m.model_identifier + "' is not a C identifier");
  m.model_name = m.model_identifier;
  m.dialect = opt.dialect;
  m.strict = opt.strict;
  m.program = opt.program;
  m.cycle_ns = opt.cycle_ns;
  rt::Schedule sched;
  std::string err;
  if (!make_schedule(app, m, &sched, &err)) throw common::InputError(err);
  m.tick_ns = sched.tick_ns();
  for (size_t i = 0; i < opt.libraries.size(); ++i) m.libraries.push_back(archived_name("lib", i, opt.libraries[i]));
  for (size_t i = 0; i < opt.sources.size(); ++i) m.sources.push_back(archived_name("src", i, opt.sources[i]));
  if (!list_ports(app, &m.ports, &err)) throw common::InputError(err);
  // The GUID fingerprints what the binary will run: the manifest and every file's text.
  common::Fnv64 h;
  h.add(write_manifest(m));
  for (const auto* list : {&opt.libraries, &opt.sources})
    for (const auto& f : *list) h.add(read_source(f));
  m.guid = "plcfi-" + h.hex();
  return m;
}

std::string model_description(const Manifest& m) {
  std::string vars, outputs, params;
  size_t index = 0;  // 1-based position of a ScalarVariable, for ModelStructure
  auto type_element = [](FmiType t, bool start) {
    if (!start) return fmt::format("<{}/>", fmi_type_name(t));
    return fmt::format("<{} start=\"{}\"/>", fmi_type_name(t), t == FmiType::Boolean ? "false" : "0");
  };
  for (size_t i = 0; i < m.ports.size(); ++i) {
    const Port& p = m.ports[i];
    ++index;
    vars += fmt::format(
        "    <ScalarVariable name=\"{}\" valueReference=\"{}\" description=\"{} : {} ({})\" causality=\"{}\" "
        "variability=\"discrete\"{}>\n      {}\n    </ScalarVariable>\n",
        xml_escape(p.path), i, xml_escape(p.address), xml_escape(p.type),
        p.input ? "what the program reads" : "what reaches the plant", p.input ? "input" : "output",
        p.input ? "" : " initial=\"calculated\"", type_element(p.fmi, p.input));
    if (!p.input) outputs += fmt::format("      <Unknown index=\"{}\"/>\n", index);
  }
  for (size_t i = 0; i < m.ports.size(); ++i) {
    const Port& p = m.ports[i];
    params += fmt::format(
        "    <ScalarVariable name=\"fault.{0}\" valueReference=\"{1}\" description=\"fault model on {0} ({2}), in "
        "plcfi's notation ({3}); empty: none\" causality=\"parameter\" variability=\"fixed\">\n"
        "      <String start=\"\"/>\n    </ScalarVariable>\n"
        "    <ScalarVariable name=\"fault_at.{0}\" valueReference=\"{4}\" description=\"time of the fault on {0} (s): "
        "it acts from the first scan at or after it\" causality=\"parameter\" variability=\"fixed\">\n"
        "      <Real start=\"0\"/>\n    </ScalarVariable>\n",
        xml_escape(p.path), kFaultRef + i, xml_escape(p.address),
        p.input ? "a sensor fault: stuck, stuck_at(v), frozen, offset(d), drift(r/s), delay(t), ..."
                : "an actuator fault: no_effect, stuck_on, stuck_off, delayed(t)",
        kFaultAtRef + i);
  }
  params += fmt::format(
      "    <ScalarVariable name=\"seed\" valueReference=\"{}\" description=\"seed of the random fault models (noise, "
      "intermittent(random, ...))\" causality=\"parameter\" variability=\"fixed\">\n      <Integer start=\"1\"/>\n"
      "    </ScalarVariable>\n",
      kSeedRef);
  return fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{name}\" guid=\"{guid}\"\n"
      "  description=\"PLC program {name} ({sources}), exported by plcfi export-fmu: its tasks run in each fmi2DoStep "
      "at a base tick of {tick} s\"\n"
      "  generationTool=\"plcfi\" variableNamingConvention=\"flat\" numberOfEventIndicators=\"0\">\n"
      "  <CoSimulation modelIdentifier=\"{id}\" needsExecutionTool=\"false\" "
      "canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"false\" maxOutputDerivativeOrder=\"0\" "
      "canRunAsynchronuously=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\" "
      "canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"false\" "
      "providesDirectionalDerivative=\"false\"/>\n"
      "  <LogCategories>\n"
      "    <Category name=\"logStatusWarning\" description=\"the program stopped (a trap): outputs in the safe state\"/>\n"
      "    <Category name=\"logStatusError\" description=\"a call refused: wrong value, parameter or sequence\"/>\n"
      "    <Category name=\"logAll\" description=\"faults as they are injected (with debug logging on)\"/>\n"
      "  </LogCategories>\n"
      "  <DefaultExperiment startTime=\"0\" stepSize=\"{tick}\"/>\n"
      "  <ModelVariables>\n{vars}{params}  </ModelVariables>\n"
      "  <ModelStructure>\n{outs_block}{init_block}  </ModelStructure>\n"
      "</fmiModelDescription>\n",
      fmt::arg("name", xml_escape(m.model_name)), fmt::arg("guid", m.guid), fmt::arg("id", m.model_identifier),
      fmt::arg("sources", xml_escape(fmt::format("{} source file{}", m.sources.size(), m.sources.size() == 1 ? "" : "s"))),
      fmt::arg("tick", number(static_cast<double>(m.tick_ns) * 1e-9)), fmt::arg("vars", vars),
      fmt::arg("params", params),
      fmt::arg("outs_block", outputs.empty() ? "" : "    <Outputs>\n" + outputs + "    </Outputs>\n"),
      fmt::arg("init_block", outputs.empty() ? "" : "    <InitialUnknowns>\n" + outputs + "    </InitialUnknowns>\n"));
}

void write_program_fmu(const Manifest& m, const ExportOptions& opt) {
  std::error_code ec;
  if (!fs::is_regular_file(opt.binary, ec))
    throw common::InputError(
        fmt::format("{}: the FMU binary is missing (it is built with plcfi: target plcfi_program_fmu)", opt.binary));
  std::vector<plant::fmu::ArchiveEntry> entries;
  entries.push_back({"modelDescription.xml", model_description(m), ""});
  entries.push_back({fmt::format("binaries/linux64/{}.so", m.model_identifier), "", opt.binary});
  entries.push_back({"resources/plcfi/program.txt", write_manifest(m), ""});
  for (size_t i = 0; i < opt.libraries.size(); ++i)
    entries.push_back({"resources/plcfi/" + m.libraries[i], read_source(opt.libraries[i]), ""});
  for (size_t i = 0; i < opt.sources.size(); ++i)
    entries.push_back({"resources/plcfi/" + m.sources[i], read_source(opt.sources[i]), ""});
  plant::fmu::write_fmu_archive(opt.out, entries);
}

}  // namespace plcfi::fmu
