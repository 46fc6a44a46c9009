// FMU plants: modelDescription.xml and plant-file readers, the loader and the checked call
// sequence on the FMUs the tests build from C (tests/plant_model/fmu), and ST plants.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/yaml.hpp"
#include "io/sim/plant_factory.hpp"
#include "plant_model/fmu/fmu_plant.hpp"
#include "plant_model/fmu/model_description.hpp"
#include "plant_model/plant_file.hpp"

namespace plcfi::plant {
namespace {

namespace fs = std::filesystem;
using fmu::parse_model_description;

const std::string kFmuDir = PLCFI_TEST_FMU_DIR;

// The message of the InputError that f throws ("" when it throws none).
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const common::InputError& e) {
    return e.what();
  }
  return "";
}

const char* kMinimal = R"(<?xml version="1.0"?>
<fmiModelDescription fmiVersion="2.0" modelName="m" guid="{1}">
  <CoSimulation modelIdentifier="m"/>
  <DefaultExperiment stepSize="0.01" stopTime="5"/>
  <ModelVariables>
    <ScalarVariable name="u" valueReference="1" causality="input"><Boolean start="false"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="1" causality="output"><Real/></ScalarVariable>
    <ScalarVariable name="k" valueReference="2" causality="parameter" variability="fixed"><Integer start="3"/></ScalarVariable>
  </ModelVariables>
</fmiModelDescription>
)";

TEST(ModelDescription, ReadsWhatAPlantNeeds) {
  auto md = parse_model_description(kMinimal, "m.fmu/modelDescription.xml");
  EXPECT_EQ(md.model_identifier, "m");
  EXPECT_EQ(md.guid, "{1}");
  ASSERT_TRUE(md.default_step);
  EXPECT_DOUBLE_EQ(*md.default_step, 0.01);
  ASSERT_EQ(md.variables.size(), 3u);
  const auto* y = md.find("y");
  ASSERT_NE(y, nullptr);
  EXPECT_EQ(y->type, fmu::VarType::Real);
  EXPECT_EQ(y->causality, fmu::Causality::Output);
  EXPECT_EQ(y->line, 7u);
  EXPECT_EQ(md.find("k")->start, "3");
}

TEST(ModelDescription, ErrorsNameFileLineAndColumn) {
  auto error = [](std::string text) {
    return input_error([&] { parse_model_description(text, "x.fmu/modelDescription.xml"); });
  };
  std::string s = kMinimal;
  EXPECT_EQ(error(s.substr(0, 200)), "x.fmu/modelDescription.xml:6:5: XML error: Could not determine tag type");
  auto with = [&](const std::string& from, const std::string& to) {
    std::string t = s;
    t.replace(t.find(from), from.size(), to);
    return error(t);
  };
  EXPECT_EQ(with("fmiVersion=\"2.0\"", "fmiVersion=\"1.0\""),
            "x.fmu/modelDescription.xml:2:1: fmiVersion '1.0': plcfi loads FMI 2.0 co-simulation FMUs (FMI 1.0 is "
            "not supported: export the model as FMI 2.0)");
  EXPECT_NE(with("fmiVersion=\"2.0\"", "fmiVersion=\"3.0\"").find("FMI 3.0 is not supported yet"), std::string::npos);
  EXPECT_NE(with("<CoSimulation modelIdentifier=\"m\"/>", "<ModelExchange modelIdentifier=\"m\"/>")
                .find(":2:1: a Model Exchange FMU"),
            std::string::npos);
  EXPECT_EQ(with("name=\"k\"", "name=\"y\""), "x.fmu/modelDescription.xml:8:5: a second variable named 'y'");
  EXPECT_EQ(with("valueReference=\"2\"", "valueReference=\"-2\""),
            "x.fmu/modelDescription.xml:8:5: variable 'k': valueReference: expected an unsigned integer, got '-2'");
  EXPECT_EQ(with("<Integer start=\"3\"/>", "<Integer start=\"3.5\"/>"),
            "x.fmu/modelDescription.xml:8:91: variable 'k': start: expected a 32-bit integer, got '3.5'");
  EXPECT_EQ(with("causality=\"parameter\"", "causality=\"param\""),
            "x.fmu/modelDescription.xml:8:5: ScalarVariable causality: expected parameter, calculatedParameter, input, "
            "output, local or independent, got 'param'");
  EXPECT_NE(with("modelIdentifier=\"m\"", "modelIdentifier=\"../m\"").find("is not a valid file name"), std::string::npos);
}

TEST(ModelDescription, ManyVariablesAreReadAndTooManyAreAnError) {
  auto doc = [](size_t n) {
    std::string t = "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"m\" guid=\"g\">\n"
                    "<CoSimulation modelIdentifier=\"m\"/>\n<ModelVariables>\n";
    for (size_t i = 0; i < n; ++i)
      t += "<ScalarVariable name=\"v" + std::to_string(i) + "\" valueReference=\"" + std::to_string(i) +
           "\" causality=\"output\"><Real/></ScalarVariable>\n";
    return t + "</ModelVariables>\n</fmiModelDescription>\n";
  };
  auto md = parse_model_description(doc(100'000), "big.xml");
  ASSERT_EQ(md.variables.size(), 100'000u);
  EXPECT_EQ(md.variables.back().line, 100'003u);  // positions counted on, not from the start each time
  EXPECT_EQ(input_error([&] { parse_model_description(doc(100'001), "big.xml"); }),
            "big.xml:100004:1: more than 100000 variables");
}

class PlantFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("plcfi_plantfile_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  std::string error(const std::string& text) {
    const std::string p = write("p.yaml", text);
    return input_error([&] { read_plant_file(p); });
  }
  fs::path dir_;
};

TEST_F(PlantFileTest, ReadsAnFmuPlant) {
  const std::string p = write("p.yaml",
                              "fmu: sub/conveyor.fmu\nstep: 5ms\nstop_time: 1h\nparameters: {Speed: 0.5}\nmap:\n"
                              "  - {image: \"%QX0.0\", plant: Motor}\n"
                              "  - {image: \"%IW4\", plant: BeltSpeed, scale: {from: [0, 1], to: [0, 27648]}}\n");
  PlantFile pf = read_plant_file(p);
  EXPECT_EQ(pf.kind, PlantFile::Kind::Fmu);
  EXPECT_EQ(pf.fmu, (dir_ / "sub/conveyor.fmu").string());
  EXPECT_EQ(pf.step_ns, 5'000'000);
  EXPECT_EQ(pf.stop_time_ns, 3600'000'000'000);
  ASSERT_EQ(pf.parameters.size(), 1u);
  EXPECT_EQ(pf.parameters[0].value, "0.5");
  ASSERT_EQ(pf.map.size(), 2u);
  EXPECT_FALSE(pf.map[0].input);
  EXPECT_TRUE(pf.map[0].bit);
  EXPECT_TRUE(pf.map[1].input);
  ASSERT_TRUE(pf.map[1].scale);
  EXPECT_DOUBLE_EQ(pf.map[1].scale->to_image(0.5), 13824.0);
  EXPECT_DOUBLE_EQ(pf.map[1].scale->to_plant(13824.0), 0.5);
  EXPECT_EQ(pf.map[1].plant_where, p + ":7:28");
}

TEST_F(PlantFileTest, EveryMistakeIsAnErrorAtItsPlace) {
  const std::string p = (dir_ / "p.yaml").string();
  EXPECT_EQ(error("fmu: a.fmu\nbuiltin: stamping\nmap: []\n"),
            p + ":1:1: the plant file names more than one plant: give one of builtin:, fmu: or st:");
  EXPECT_EQ(error("step: 1ms\n"), p + ":1:1: the plant file names no plant: give one of builtin:, fmu: or st:");
  EXPECT_EQ(error("fmu: a.fmu\n"), p + ":1:1: missing key 'map' in the plant file (which image entry is which plant variable)");
  EXPECT_EQ(error("fmu: a.fmu\nmap:\n  - {image: \"%IX0.8\", plant: x}\n"),
            p + ":3:13: image: expected a bit (%IX0.0, %QX1.7) or a word (%IW2, %QW0), got '%IX0.8'");
  EXPECT_EQ(error("fmu: a.fmu\nmap:\n  - {image: \"%IX0.1\", plant: x}\n  - {image: \"%IX0.1\", plant: y}\n"),
            p + ":4:13: image: %IX0.1 is mapped twice");
  EXPECT_EQ(error("fmu: a.fmu\nmap:\n  - {image: \"%IX0.1\", plant: x, scale: {from: [0, 1], to: [0, 1]}}\n"),
            p + ":3:40: scale: %IX0.1 is a bit; only a word (%IW/%QW) takes a scale");
  EXPECT_EQ(error("fmu: a.fmu\nmap:\n  - {image: \"%IW1\", plant: x, scale: {from: [1, 1], to: [0, 1]}}\n"),
            p + ":3:45: scale.from: the two ends must differ");
  EXPECT_EQ(error("fmu: a.fmu\nmap:\n  - {image: \"%IW1\", plant: x, scale: {from: [0, 1], to: [0, 40000]}}\n"),
            p + ":3:57: scale.to: 40000 does not fit a 16-bit word (-32768..32767)");
  EXPECT_EQ(error("builtin: stamping\nstop_time: 1s\n"), p + ":2:12: stop_time: only for a plant given by fmu:");
  EXPECT_EQ(error("fmu: a.fmu\nstep: 0ms\nmap: []\n").rfind(p + ":2:7: step:", 0), 0u);
  EXPECT_EQ(error("fmu: a.fmu\nmaps: []\n").rfind(p + ":2:1: unknown key 'maps' in the plant file", 0), 0u);
}

// ---- FMUs built by the tests ----

class FmuPlantTest : public PlantFileTest {
 protected:
  // A plant file for probe.fmu with `extra` lines before its map.
  std::string probe(const std::string& extra, const std::string& map_extra = "") {
    return write("probe.yaml", "fmu: " + kFmuDir + "/probe.fmu\nstep: 10ms\n" + extra +
                                   "map:\n"
                                   "  - {image: \"%QX0.0\", plant: Enable}\n"
                                   "  - {image: \"%IX0.0\", plant: Toggle}\n"
                                   "  - {image: \"%IW2\", plant: Steps}\n"
                                   "  - {image: \"%IW4\", plant: Ramp, scale: {from: [0, 100], to: [0, 10000]}}\n" +
                                   map_extra);
  }
  std::unique_ptr<Plant> open(const std::string& path, std::string* err) { return io::open_plant(path, "", err); }
};

TEST_F(FmuPlantTest, StepsTheFmuAtItsOwnStep) {
  std::string err;
  auto p = open(probe(""), &err);
  ASSERT_TRUE(p) << err;
  ASSERT_EQ(p->signals().size(), 4u);
  EXPECT_EQ(p->step_ns(), 10'000'000);
  std::vector<double> v(4, 0.0);
  v[0] = 1.0;
  for (int i = 0; i < 150; ++i) p->step(0.01, v.data(), v.data());  // 1.5 s
  EXPECT_EQ(v[2], 150.0);      // Steps: one DoStep per 10 ms
  EXPECT_EQ(v[3], 150.0);      // Ramp = t = 1.5, scaled by 100
  EXPECT_EQ(v[1], 1.0);        // Toggle: TRUE in the second second
  p->reset(7);
  p->sense(v.data());
  EXPECT_EQ(v[2], 0.0);        // a new start
  EXPECT_EQ(v[3], 0.0);
}

TEST_F(FmuPlantTest, ACoarsePlantStepHoldsItsOutputsOverScans) {
  std::string err;
  const std::string coarse = write("coarse.yaml", "fmu: " + kFmuDir + "/probe.fmu\nstep: 50ms\nmap:\n"
                                                  "  - {image: \"%IW2\", plant: Steps}\n");
  auto p = open(coarse, &err);
  ASSERT_TRUE(p) << err;
  std::vector<double> v(1, 0.0);
  std::vector<double> seen;
  for (int i = 0; i < 10; ++i) {
    p->step(0.01, v.data(), v.data());
    seen.push_back(v[0]);
  }
  EXPECT_EQ(seen, (std::vector<double>{0, 0, 0, 0, 1, 1, 1, 1, 1, 2}));
  // probe.fmu suggests 10 ms (DefaultExperiment stepSize): the other step is noted.
  EXPECT_EQ(p->notes(), (std::vector<std::string>{
                            "the FMU's DefaultExperiment suggests a step of 10ms; the plant file steps it every 50ms"}));
}

TEST_F(FmuPlantTest, TheMapIsCheckedAgainstModelDescription) {
  std::string err;
  const std::string md = kFmuDir + "/probe.fmu/modelDescription.xml";
  EXPECT_FALSE(open(probe("", "  - {image: \"%IX0.1\", plant: Nothing}\n"), &err));
  EXPECT_EQ(err, (dir_ / "probe.yaml").string() + ":8:30: the FMU has no variable 'Nothing' (its outputs: Ramp, Toggle, Steps, EnableEcho)");
  EXPECT_FALSE(open(probe("", "  - {image: \"%IX0.1\", plant: FailAt}\n"), &err));
  EXPECT_NE(err.find(":8:30: 'FailAt' is a parameter of the FMU (" + md + ":"), std::string::npos) << err;
  EXPECT_NE(err.find("%IX0.1 takes an output (what the plant tells the PLC)"), std::string::npos) << err;
  EXPECT_FALSE(open(probe("", "  - {image: \"%IW6\", plant: EnableEcho}\n"), &err));
  EXPECT_NE(err.find(":8:5: 'EnableEcho' is Boolean"), std::string::npos) << err;
  EXPECT_FALSE(open(probe("", "  - {image: \"%IW6\", plant: Ramp}\n"), &err));
  EXPECT_NE(err.find(":8:5: 'Ramp' is Real (" + md + ":"), std::string::npos) << err;
  EXPECT_NE(err.find("a word needs scale"), std::string::npos) << err;
  EXPECT_FALSE(open(probe("parameters: {FailAt: soon}\n"), &err));
  EXPECT_EQ(err, (dir_ / "probe.yaml").string() + ":3:22: 'FailAt' is Real: expected a number, got 'soon'");
  EXPECT_FALSE(open(probe("parameters: {Ramp: 1}\n"), &err));
  EXPECT_NE(err.find(":3:20: 'Ramp' is an output of the FMU"), std::string::npos) << err;
  EXPECT_FALSE(open(probe("seed_parameter: FailAt\n"), &err));
  EXPECT_NE(err.find(":3:17: seed_parameter: the FMU has no Integer parameter 'FailAt'"), std::string::npos) << err;
}

TEST_F(FmuPlantTest, BrokenArchivesArePreciseErrors) {
  struct Case {
    const char* fmu;
    std::string expect;
  } cases[] = {
      {"probe_bad_xml", "/probe_bad_xml.fmu/modelDescription.xml:"},
      {"probe_fmi1", "fmiVersion '1.0'"},
      {"probe_fmi3", "fmiVersion '3.0'"},
      {"probe_no_binary", "no binary for this platform: binaries/linux64/probe.so is missing"},
      {"probe_no_cosim", "a Model Exchange FMU"},
      {"probe_missing_symbol", "does not define fmi2DoStep"},
      {"not_a_zip", "not an FMU (an FMU is a zip archive)"},
      {"missing", "missing.fmu: cannot open"},
  };
  for (const auto& c : cases) {
    const std::string p = write("b.yaml", std::string("fmu: ") + kFmuDir + "/" + c.fmu + ".fmu\nstep: 10ms\nmap:\n  - {image: \"%IX0.0\", plant: Toggle}\n");
    std::string err;
    EXPECT_FALSE(open(p, &err)) << c.fmu;
    EXPECT_NE(err.find(c.expect), std::string::npos) << c.fmu << ": " << err;
  }
}

TEST_F(FmuPlantTest, ADirectoryOrADeviceAsTheFmuIsAnErrorAtOnce) {
  std::string err;
  for (const std::string& target : {dir_.string(), std::string("/dev/zero")}) {
    const std::string p = write("d.yaml", "fmu: " + target + "\nstep: 10ms\nmap:\n  - {image: \"%IX0.0\", plant: Toggle}\n");
    EXPECT_FALSE(open(p, &err)) << target;
    EXPECT_EQ(err.rfind(p + ":1:6: fmu: " + target + ": ", 0), 0u) << err;
  }
  EXPECT_NE(err.find("not a regular file"), std::string::npos) << err;
}

TEST_F(FmuPlantTest, ABuiltInPlantCanBeMappedOntoOtherAddresses) {
  const std::string p = write("b.yaml", "builtin: stamping\nmap:\n  - {image: \"%IX4.0\", plant: PosCrane}\n"
                                        "  - {image: \"%QW8\", plant: PressureSetpoint}\n");
  std::string err;
  auto plant = open(p, &err);
  ASSERT_TRUE(plant) << err;
  for (const auto& s : plant->signals()) {
    if (s.name == "PosCrane") {
      EXPECT_EQ(s.address, "%IX4.0");
    } else if (s.name == "PressureSetpoint") {
      EXPECT_EQ(s.address, "%QW8");
    } else if (s.name == "PosStamp") {
      EXPECT_EQ(s.address, "%IX0.1");  // not in the map: its own address
    }
  }
  auto error = [&](const std::string& map) {
    std::string e;
    EXPECT_FALSE(open(write("e.yaml", "builtin: stamping\nmap:\n" + map), &e));
    return e;
  };
  const std::string e = (dir_ / "e.yaml").string();
  EXPECT_EQ(error("  - {image: \"%IX4.0\", plant: Nope}\n").rfind(e + ":3:30: the plant stamping has no signal 'Nope'", 0), 0u);
  EXPECT_EQ(error("  - {image: \"%QX4.0\", plant: PosCrane}\n"),
            e + ":3:5: 'PosCrane' is a sensor of stamping: it belongs in %I");
  EXPECT_EQ(error("  - {image: \"%IW4\", plant: PosCrane}\n"),
            e + ":3:5: 'PosCrane' is a BOOL signal: map it to a bit (%IX...), not %IW4");
  EXPECT_EQ(error("  - {image: \"%IW4\", plant: StampPressure, scale: {from: [0, 1], to: [0, 10]}}\n"),
            e + ":3:50: scale: 'StampPressure' is an analog signal in image units; only a real-valued variable is scaled");
}

TEST_F(FmuPlantTest, FailuresInTheRunNameTheCallAndTheTime) {
  auto run_until_error = [&](const std::string& params, double seconds) -> std::string {
    std::string err;
    auto p = open(probe(params), &err);
    if (!p) return "open: " + err;
    std::vector<double> v(4, 0.0);
    try {
      for (int i = 0; i < static_cast<int>(seconds * 100); ++i) p->step(0.01, v.data(), v.data());
    } catch (const fmu::FmuError& e) {
      return e.what();
    }
    return "";
  };
  std::string e = run_until_error("parameters: {FailAt: 0.5}\n", 1);
  EXPECT_NE(e.find("fmi2DoStep(t = 0.5 s, h = 0.01 s) returned fmi2Error (the FMU logged: step failed"), std::string::npos) << e;
  e = run_until_error("parameters: {EndAt: 0.3}\n", 1);
  EXPECT_NE(e.find("returned fmi2Discard: the FMU ended its simulation at t = 0.3 s"), std::string::npos) << e;
  e = run_until_error("parameters: {CrashAt: 0.2}\n", 1);
  EXPECT_NE(e.find("fmi2DoStep crashed inside the FMU (Segmentation fault, signal 11)"), std::string::npos) << e;
  e = run_until_error("call_timeout: 300ms\nparameters: {HangAt: 0.3}\n", 1);
  EXPECT_NE(e.find("fmi2DoStep did not return within 300ms (the FMU hangs"), std::string::npos) << e;
  e = run_until_error("stop_time: 0.4s\nparameters: {NeedStopTime: true}\n", 1);
  EXPECT_NE(e.find("goes past the stop time"), std::string::npos) << e;
  e = run_until_error("parameters: {NeedStopTime: true}\n", 1);
  EXPECT_NE(e.find("needs a stop time"), std::string::npos) << e;
}

// An FMU that calls exit(0) inside a call ends plcfi with status 2 and a message naming
// the FMU and the call, never with the FMU's own status.
TEST_F(FmuPlantTest, ExitInsideACallEndsWithStatusTwo) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        std::string err;
        auto p = open(probe("parameters: {ExitAt: 0.2}\n"), &err);
        std::vector<double> v(4, 0.0);
        for (int i = 0; p && i < 100; ++i) p->step(0.01, v.data(), v.data());
        std::exit(0);  // reached only if the FMU did not exit
      },
      ::testing::ExitedWithCode(2), "probe.fmu: fmi2DoStep ended the process \\(exit\\(\\) inside the FMU\\)");
}

TEST_F(FmuPlantTest, AnStPlantRunsAtItsStep) {
  write("counter.st",
        "PROGRAM Counter\nVAR_INPUT Run : BOOL; END_VAR\nVAR_OUTPUT Ticks : INT; Level : REAL; Up : BOOL; END_VAR\n"
        "VAR Rate : REAL := 1.0; END_VAR\n"
        "IF Run THEN Ticks := Ticks + 1; Level := Level + Rate * 0.01; END_IF;\nUp := Level >= 0.5;\nEND_PROGRAM\n");
  const std::string p = write("st.yaml",
                              "st: counter.st\nstep: 10ms\nparameters: {Rate: 2.0}\nmap:\n"
                              "  - {image: \"%QX0.0\", plant: Run}\n"
                              "  - {image: \"%IW2\", plant: Ticks}\n"
                              "  - {image: \"%IW4\", plant: Level, scale: {from: [0, 1], to: [0, 1000]}}\n"
                              "  - {image: \"%IX0.0\", plant: Up}\n");
  std::string err;
  auto plant = open(p, &err);
  ASSERT_TRUE(plant) << err;
  std::vector<double> v(4, 0.0);
  v[0] = 1.0;
  for (int i = 0; i < 5; ++i) plant->step(0.05, v.data(), v.data());  // 25 plant scans
  EXPECT_EQ(v[1], 25.0);
  EXPECT_NEAR(v[2], 500.0, 0.5);
  EXPECT_EQ(v[3], 1.0);
  plant->reset(1);
  plant->sense(v.data());
  EXPECT_EQ(v[1], 0.0);

  const std::string bad = write("bad.yaml", "st: counter.st\nstep: 10ms\nmap:\n  - {image: \"%IX0.0\", plant: Ticks}\n");
  EXPECT_FALSE(open(bad, &err));
  EXPECT_EQ(err, bad + ":4:5: 'Ticks' is INT: map it to a word (%IW...), not the bit %IX0.0");
  write("broken.st", "PROGRAM P\nx := ;\nEND_PROGRAM\n");
  const std::string nocompile = write("nc.yaml", "st: broken.st\nstep: 10ms\nmap:\n  - {image: \"%IX0.0\", plant: x}\n");
  EXPECT_FALSE(open(nocompile, &err));
  EXPECT_NE(err.find("broken.st:2:"), std::string::npos) << err;
  EXPECT_NE(err.find(nocompile + ":1:1: the ST plant does not compile"), std::string::npos) << err;
}

}  // namespace
}  // namespace plcfi::plant
