// plcfi merge: the shard files of a campaign (campaign --shard K/N) into the journal the
// campaign writes when one process runs it.
#include <filesystem>
#include <iostream>
#include <sstream>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "campaign/mutate.hpp"
#include "campaign/parallel.hpp"
#include "common/file.hpp"
#include "common/json.hpp"
#include "commands.hpp"
#include "options.hpp"

namespace po = boost::program_options;

namespace plcfi::cli {

namespace {

// The first line of a `plcfi mutate --shard` journal says {"plcfi":"mutants",...}.
bool is_mutation_journal(const std::string& path) {
  std::string text, err;
  if (!common::read_file(path, common::kMaxJournalBytes, &text, &err)) return false;
  common::Json j;
  size_t column = 0;
  if (!common::json_parse(text.substr(0, text.find('\n')), &j, &err, &column) || !j.is_object()) return false;
  auto it = j.find("plcfi");
  return it != j.end() && it->is_string() && it->get<std::string>() == "mutants";
}

int merge_mutants(const std::vector<std::string>& files, const std::string& out) {
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  const std::string path = (std::filesystem::path(out) / "mutants.jsonl").string();
  std::string err;
  if (!campaign::merge_mutant_journals(files, path, &err)) {
    std::cerr << "plcfi merge: " << err << "\n";
    return 2;
  }
  std::string text;
  if (!common::read_file(path, common::kMaxJournalBytes, &text, &err)) {
    std::cerr << "plcfi merge: " << err << "\n";
    return 2;
  }
  size_t killed = 0, survived = 0, equivalent = 0;
  std::istringstream lines(text);
  std::string line;
  std::getline(lines, line);  // the header
  while (std::getline(lines, line)) {
    common::Json j;
    size_t column = 0;
    if (!common::json_parse(line, &j, &err, &column) || !j.is_object() || !j.contains("status")) continue;
    // Fields as a shard wrote them; a field of another type reads as empty, never throws.
    auto field = [&](const char* k) { return j.contains(k) && j[k].is_string() ? j[k].get<std::string>() : std::string(); };
    auto number = [&](const char* k) { return j.contains(k) && j[k].is_number_unsigned() ? j[k].get<uint64_t>() : 0; };
    const std::string st = field("status");
    if (st == "killed") ++killed;
    else if (st == "survived") {
      ++survived;
      std::cout << fmt::format("  survived #{} {}:{}:{} [{}] {}\n", number("index"), field("file"), number("line"), number("col"),
                               field("operator"), field("change"));
    } else if (st == "equivalent") ++equivalent;
  }
  const size_t judged = killed + survived;
  std::cout << fmt::format("plcfi merge: {} mutation shard journal(s): {} killed, {} survived, {} equivalent; score {:.1f} %\n",
                           files.size(), killed, survived, equivalent,
                           judged ? 100.0 * static_cast<double>(killed) / static_cast<double>(judged) : 100.0);
  std::cout << "journal " << path << "\n";
  return 0;
}

}  // namespace

int cmd_merge(const std::vector<std::string>& args) {
  const std::string usage = "plcfi merge --out DIR SHARD_FILE...   (campaign shard files, or plcfi mutate --shard journals)";
  po::options_description desc(
      "plcfi merge: combine the N shard files of a campaign (plcfi campaign --shard K/N) into DIR/results.jsonl, the "
      "journal one process running the whole campaign writes; or the mutants.jsonl journals of plcfi mutate --shard K/N into "
      "DIR/mutants.jsonl, the journal of one run");
  desc.add_options()("out", po::value<std::string>(), "output folder for results.jsonl (required)");
  po::variables_map vm;
  if (!parse_args(args, desc, vm, usage)) return 0;
  if (!vm.count("out") || !vm.count("files")) {
    std::cerr << "plcfi merge: expected --out DIR and the shard files\nusage: " << usage << "\n";
    return 2;
  }
  const auto files = vm["files"].as<std::vector<std::string>>();
  const std::string out = vm["out"].as<std::string>();
  if (is_mutation_journal(files.front())) return merge_mutants(files, out);
  const std::string journal = (std::filesystem::path(out) / "results.jsonl").string();
  campaign::MergeResult m;
  std::string err;
  if (!campaign::merge_shards(files, journal, &m, &err)) {
    std::cerr << "plcfi merge: " << err << "\n";
    return 2;
  }
  size_t pass = 0, fail = 0;
  std::cout << fmt::format("plcfi merge: campaign {}, {} shard file(s)\n\n", m.campaign, files.size());
  for (const auto& e : m.executions) {
    (e.verdict == "PASS" ? pass : fail)++;
    std::cout << fmt::format("  [run {:>2}] {} path {} {}: {}\n", e.run, e.case_id, e.path, e.verdict, e.transition);
    if (e.verdict != "PASS") std::cout << "           " << e.reason << "\n";
  }
  for (const auto& id : m.not_reached) std::cout << fmt::format("  {} NOT REACHED\n", id);
  const auto& p = m.progress;
  std::cout << fmt::format("\n{} execution(s) of {} case(s): {} PASS, {} FAIL, {} NOT REACHED\n", m.executions.size(), m.cases,
                           pass, fail, m.not_reached.size());
  std::cout << fmt::format("{} run(s), {} scans, {:.1f} s on the scan clock; ended: {}\n", p.run, p.scans,
                           static_cast<double>(p.campaign_ns) * 1e-9, m.end_reason);
  std::cout << fmt::format("journal {}, {} trace(s) copied from the shard folders\n", journal, m.traces_copied);
  if (!m.traces_missing.empty()) {
    std::cout << fmt::format("{} trace(s) not found beside their shard file:\n", m.traces_missing.size());
    for (const auto& t : m.traces_missing) std::cout << "  " << t << "\n";
  }
  return fail || !m.not_reached.empty() ? 1 : 0;
}

}  // namespace plcfi::cli
