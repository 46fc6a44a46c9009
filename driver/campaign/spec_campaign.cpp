// The campaign file: which program, plant, specs (TSD, FMEA, fault classes) and search
// limits; it names the other files relative to its own folder.
#include <filesystem>

#include "campaign/spec_internal.hpp"
#include "plant_model/plant_file.hpp"

namespace plcfi::campaign {

namespace {

std::string relative_to(const std::string& base_file, const std::string& p) {
  std::filesystem::path path(p);
  if (path.is_absolute()) return p;
  return (std::filesystem::path(base_file).parent_path() / path).lexically_normal().string();
}

void parse_campaign(const common::YamlDoc& f, Campaign* c) {
  f.check_keys(f.root(),
         {"campaign", "text", "program", "dialect", "plant", "plant_config", "cycle", "tsd", "fmea", "fault_classes", "seed", "budget",
          "max_paths", "search_window", "restart", "io", "explore", "requirements"},
         "a campaign file");
  c->path = f.path();
  c->name = f.scalar(f.required(f.root(), "campaign", "a campaign file"), "campaign");
  if (f.root()["text"]) c->text = f.scalar(f.root()["text"], "text");
  YAML::Node prog = f.required(f.root(), "program", "a campaign file");
  if (prog.IsScalar()) {
    c->programs.push_back(relative_to(f.path(), prog.Scalar()));
  } else if (prog.IsSequence() && prog.size() > 0) {
    for (const auto& p : prog) c->programs.push_back(relative_to(f.path(), f.scalar(p, "a program file")));
  } else {
    f.fail(prog, "program: expected a file or a list of files, got " + common::YamlDoc::describe(prog));
  }
  if (f.root()["dialect"]) c->dialect = f.word(f.root()["dialect"], "dialect", {"iec", "codesys"});
  c->plant = f.scalar(f.required(f.root(), "plant", "a campaign file"), "plant");
  // A plant file (tank.yaml) is found relative to the campaign file; a built-in plant by name.
  if (plant::is_plant_file(c->plant)) c->plant = relative_to(f.path(), c->plant);
  if (f.root()["plant_config"]) c->plant_config = relative_to(f.path(), f.scalar(f.root()["plant_config"], "plant_config"));
  if (f.root()["cycle"]) c->cycle_ns = f.duration(f.root()["cycle"], "cycle", 1);
  if (f.root()["seed"]) c->seed = static_cast<uint64_t>(f.integer(f.root()["seed"], "seed", 0));
  if (f.root()["budget"]) c->budget_ns = f.duration(f.root()["budget"], "budget", 1);
  if (f.root()["max_paths"]) c->max_paths = static_cast<int>(f.integer(f.root()["max_paths"], "max_paths", 1, 64));
  if (f.root()["search_window"]) c->search_window_ns = f.duration(f.root()["search_window"], "search_window", 1);
  if (f.root()["restart"])
    c->restart = f.word(f.root()["restart"], "restart", {"cold", "warm"}) == "warm" ? RestartKind::Warm : RestartKind::Cold;
  if (f.root()["io"]) c->io = relative_to(f.path(), f.scalar(f.root()["io"], "io"));
  if (f.root()["requirements"]) c->requirements = relative_to(f.path(), f.scalar(f.root()["requirements"], "requirements"));
  std::string tsd = relative_to(f.path(), f.scalar(f.required(f.root(), "tsd", "a campaign file"), "tsd"));
  std::string fmea = relative_to(f.path(), f.scalar(f.required(f.root(), "fmea", "a campaign file"), "fmea"));
  std::string classes =
      relative_to(f.path(), f.scalar(f.required(f.root(), "fault_classes", "a campaign file"), "fault_classes"));
  detail::parse_tsd(common::YamlDoc::open(tsd), &c->tsd);
  detail::parse_fmea(fmea, &c->fmea);
  detail::parse_classes(common::YamlDoc::open(classes), &c->classes);
  c->explore.loc = Loc{f.path(), 1, 1};
  if (YAML::Node ex = f.root()["explore"]) {
    c->explore.loc = detail::loc_of(f, ex);
    f.check_keys(ex, {"enabled", "default_class"}, "the explore section", true);
    if (ex.IsMap()) {
      if (ex["enabled"]) c->explore.enabled = f.boolean(ex["enabled"], "explore: enabled");
      if (YAML::Node dc = ex["default_class"]) {
        c->explore.default_class = f.scalar(dc, "explore: default_class");
        c->explore.class_loc = detail::loc_of(f, dc);
        if (!c->classes.find(c->explore.default_class))
          f.fail(dc, "explore: default_class '" + c->explore.default_class + "' is not defined in " + c->classes.path);
      }
    }
  }
}

}  // namespace

bool load_campaign(const std::string& path, Campaign* out, std::string* err) {
  if (!common::catch_input_error(err, [&] { parse_campaign(common::YamlDoc::open(path), out); })) return false;
  return check_references(*out, err);
}

}  // namespace plcfi::campaign
