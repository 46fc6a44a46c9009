// plcfi mutate: mutation analysis of a program's error handling against a campaign.
#include <cstdio>
#include <filesystem>
#include <iostream>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "campaign/generate.hpp"
#include "campaign/mutate.hpp"
#include "campaign/parallel.hpp"
#include "commands.hpp"
#include "report/campaign_html.hpp"
#include "report/html.hpp"
#include "common/json.hpp"
#include "options.hpp"

namespace po = boost::program_options;

namespace plcfi::cli {

namespace {

// The options of `plcfi mutate`.
void add_mutate_options(po::options_description& desc) {
  desc.add_options()
      ("program", po::value<std::vector<std::string>>()->multitoken(), "program files instead of the campaign's")
      ("explore", "judge the mutants by the explored campaign (campaign --explore): the FMEA's cases and the explored ones")
      ("seed", po::value<Count>(), "seed instead of the campaign's")
      ("jobs,j", po::value<IntIn<1, 256>>()->default_value(IntIn<1, 256>{1}, "1"), "worker processes judging mutants (same output as 1)")
      ("shard", po::value<std::string>(), "judge only the mutants with index % N == K (K from 0 to N-1); combine the journals with merge")
      ("out", po::value<std::string>(), "write DIR/mutants.jsonl (a header line, one line per mutant)")
      ("json", "print the journal lines instead of the text report")
      ("list", "list the mutants without running the campaign")
      ("min-score", po::value<double>(), "exit 1 when the mutation score (percent) is below P")
      ("html", po::value<std::string>(), "write a self-contained HTML report (DIR/index.html): score, every mutant, survivors first, the TSD");
}

// --jobs, --shard and --min-score (*min_score -1: none). False after printing why.
bool mutate_options(const po::variables_map& vm, campaign::MutateOptions* opt, double* min_score) {
  opt->jobs = static_cast<unsigned>(vm["jobs"].as<IntIn<1, 256>>().value);
  std::string err;
  if (vm.count("shard")) {
    int k = 0, n = 0;
    if (!campaign::parse_share(vm["shard"].as<std::string>(), &k, &n, &err)) {
      std::cerr << "plcfi mutate: --shard " << err << "\n";
      return false;
    }
    opt->shard = static_cast<unsigned>(k);
    opt->shards = static_cast<unsigned>(n);
  }
  if (vm.count("min-score")) {
    *min_score = vm["min-score"].as<double>();
    if (!(*min_score >= 0 && *min_score <= 100)) {
      std::cerr << "plcfi mutate: option '--min-score': a percentage from 0 to 100\n";
      return false;
    }
  }
  return true;
}

// The folders of --html and --out, before the work, not after it: a bad folder is bad
// usage. False after printing why.
bool make_output_folders(const po::variables_map& vm, campaign::MutateOptions* opt) {
  std::string err;
  if (vm.count("html") && !report::html_dir_writable(vm["html"].as<std::string>(), &err)) {
    std::cerr << "plcfi mutate: " << err << "\n";
    return false;
  }
  if (vm.count("out")) {
    opt->out_dir = vm["out"].as<std::string>();
    std::error_code ec;
    std::filesystem::create_directories(opt->out_dir, ec);
    if (ec) {
      std::cerr << "plcfi mutate: " << opt->out_dir << ": cannot create the output folder: " << ec.message() << "\n";
      return false;
    }
  }
  return true;
}

// The campaign that judges the mutants, with --program, --seed and --explore, prepared.
// False after printing why.
bool prepare_judge(const po::variables_map& vm, campaign::CampaignBuild* cb) {
  campaign::Campaign spec;
  std::string err;
  const std::string path = vm["campaign-file"].as<std::vector<std::string>>()[0];
  if (!campaign::load_campaign(path, &spec, &err)) {
    std::cerr << err << "\n";
    return false;
  }
  if (vm.count("program")) spec.programs = vm["program"].as<std::vector<std::string>>();
  if (vm.count("seed")) spec.seed = vm["seed"].as<Count>().value;
  // Campaign options that change what runs per mutant are set on the spec here, before the
  // one preparation: every mutant runs the same campaign.
  if (vm.count("explore")) spec.explore.enabled = true;
  // A mutant negates, drops or forces the one conditional jump of an IF, or removes the one
  // store of an assignment (mutate_gen.cpp): conditions compiled as chains of jumps and
  // assignments copied into arms would have several.
  spec.for_mutation = true;
  if (!campaign::prepare_campaign(std::move(spec), cb, &err)) {
    std::cerr << err << (err.empty() || err.back() == '\n' ? "" : "\n");
    return false;
  }
  return true;
}

// --list: the mutants, without running the campaign.
void list_mutants(const campaign::CampaignBuild& cb) {
  auto mutants = campaign::generate_mutants(cb);
  for (const auto& m : mutants)
    std::cout << fmt::format("#{:<3} {}:{}:{} [{}] {}{}\n", m.index, m.file, m.line, m.col, campaign::mutation_op_name(m.op),
                             m.change, m.equivalent ? "  (equivalent: " + m.proof + ")" : "");
  std::cout << fmt::format("{} mutant(s)\n", mutants.size());
}

// The journal's lines (--json), else the text report.
void print_mutation(const po::variables_map& vm, const campaign::CampaignBuild& cb, const campaign::MutationRun& run,
                    const campaign::MutateOptions& opt) {
  if (vm.count("json")) {
    std::cout << campaign::mutation_header_line(cb, run, opt) << "\n";
    for (size_t i = 0; i < run.mutants.size(); ++i)
      if (run.evaluated[i]) std::cout << campaign::mutant_line(run.mutants[i], run.results[i]) << "\n";
  } else {
    if (opt.shards) std::cout << fmt::format("shard {}/{}: mutants with index % {} == {}\n", opt.shard, opt.shards, opt.shards, opt.shard);
    std::cout << campaign::mutation_report(cb, run);
    if (!opt.out_dir.empty()) std::cout << "journal " << opt.out_dir << "/mutants.jsonl\n";
  }
}

// A judged mutant as a row of the HTML report.
report::MutantRow mutant_row(const campaign::Mutant& m, const campaign::MutantResult& r) {
  report::MutantRow row;
  row.id = fmt::format("#{} {}", m.index, campaign::mutation_op_name(m.op));
  row.location = fmt::format("{}:{}:{}", std::filesystem::path(m.file).filename().string(), m.line, m.col);
  row.change = m.change;
  row.status = r.status == campaign::MutantStatus::Killed     ? report::MutantStatus::Killed
               : r.status == campaign::MutantStatus::Survived ? report::MutantStatus::Survived
                                                              : report::MutantStatus::Equivalent;
  row.killed_by = r.killed_by;
  row.reason = r.detail;
  return row;
}

// The HTML page: the campaign's page (header, TSD) without executions, and the mutants.
report::HtmlReport mutation_page(const campaign::CampaignBuild& cb, const campaign::MutationRun& run,
                                 const campaign::MutateOptions& opt) {
  report::HtmlReport page = report::campaign_html_model(cb, campaign::CampaignResult{}, opt.out_dir, false);
  page.rows.clear();
  page.executions.clear();
  page.waveform_note.clear();
  page.suggestions.clear();
  auto& h = page.header;
  h.title = "Mutation analysis: campaign " + h.name;
  h.executions = run.baseline.executions;
  h.pass = run.baseline.pass;
  h.fail = run.baseline.fail;
  h.not_reached = 0;
  h.end_reason = "mutation analysis: the campaign judged every mutant (interpreted VM)";
  h.facts.clear();
  const double sc = campaign::mutation_score(run);
  h.facts.emplace_back("mutation score", sc >= 0 ? fmt::format("{:.1f} %", sc * 100.0) : "no mutant to judge");
  h.facts.emplace_back("original", fmt::format("{} execution(s): {} PASS, {} FAIL", run.baseline.executions,
                                               run.baseline.pass, run.baseline.fail));
  if (opt.shards) h.facts.emplace_back("shard", fmt::format("{}/{}: this page holds its share only", opt.shard, opt.shards));
  for (size_t i = 0; i < run.mutants.size(); ++i)
    if (run.evaluated[i]) page.mutants.push_back(mutant_row(run.mutants[i], run.results[i]));
  return page;
}

// --html DIR. False after printing why.
bool write_mutation_html(const std::string& dir, const campaign::CampaignBuild& cb, const campaign::MutationRun& run,
                         const campaign::MutateOptions& opt) {
  std::string err;
  if (!report::write_html_report(mutation_page(cb, run, opt), dir, &err)) {
    std::cerr << "plcfi mutate: " << err << "\n";
    return false;
  }
  std::cout << "HTML report: " << (std::filesystem::path(dir) / "index.html").string() << "\n";
  return true;
}

}  // namespace

int cmd_mutate(const std::vector<std::string>& args) {
  const std::string usage =
      "plcfi mutate CAMPAIGN.yaml [--program FILE...] [--explore] [--seed N] [--jobs N] [--shard K/N] [--out DIR] [--json] [--list] [--min-score P] [--html DIR]";
  po::options_description desc(
      "plcfi mutate: mutation analysis of the program's error handling: mutants of the compiled program (stores to alarm/stop "
      "variables removed, their guarding conditions negated, dropped or forced FALSE, timer presets scaled, latches cleared), "
      "the campaign run on each (stop at the first kill), the score and every survivor");
  add_mutate_options(desc);
  po::variables_map vm;
  if (!parse_args(args, desc, vm, usage, "campaign-file")) return 0;
  if (!vm.count("campaign-file") || vm["campaign-file"].as<std::vector<std::string>>().size() != 1) {
    std::cerr << "plcfi mutate: expected one campaign file\nusage: " << usage << "\n";
    return 2;
  }
  campaign::MutateOptions opt;
  double min_score = -1;
  campaign::CampaignBuild cb;
  if (!mutate_options(vm, &opt, &min_score) || !make_output_folders(vm, &opt) || !prepare_judge(vm, &cb)) return 2;
  if (vm.count("list")) {
    list_mutants(cb);
    return 0;
  }

  std::fflush(stdout);  // nothing buffered may be written twice by the workers
  campaign::MutationRun run;
  std::string err;
  if (!campaign::run_mutation(cb, opt, &run, &err)) {
    std::cerr << "plcfi mutate: " << err << "\n";
    return 2;
  }
  print_mutation(vm, cb, run, opt);
  if (vm.count("html") && !write_mutation_html(vm["html"].as<std::string>(), cb, run, opt)) return 2;
  double score = campaign::mutation_score(run);
  if (min_score >= 0 && score >= 0 && score * 100.0 < min_score) {
    std::cerr << fmt::format("plcfi mutate: mutation score {:.1f} % is below --min-score {}\n", score * 100.0, min_score);
    return 1;
  }
  return 0;
}

}  // namespace plcfi::cli
