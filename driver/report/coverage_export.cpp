// Branch coverage as lcov tracefile and Cobertura XML (see coverage_export.hpp for what
// the numbers mean).
#include "coverage_export.hpp"
#include "junit.hpp"  // xml_escape

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include <fmt/format.h>

#include "codegen/compiler.hpp"

namespace plcfi::report {

size_t FileCoverage::branches() const {
  size_t n = 0;
  for (const auto& d : decisions) n += d.arms.size();
  return n;
}

size_t FileCoverage::branches_taken() const {
  size_t n = 0;
  for (const auto& d : decisions)
    for (const auto& a : d.arms) n += a && *a > 0;
  return n;
}

size_t FileCoverage::lines_hit() const {
  size_t n = 0;
  for (const auto& [line, hits] : lines) n += hits > 0;
  return n;
}

std::vector<FileCoverage> coverage_by_file(const st::Application& app, const std::vector<uint64_t>& hits,
                                           const std::vector<uint32_t>& files) {
  const std::set<uint32_t> wanted(files.begin(), files.end());
  auto count = [&](uint32_t id) { return id < hits.size() ? hits[id] : 0; };
  // Arms per decision, in id order (the order of the source).
  std::map<uint32_t, std::vector<uint32_t>> decisions;
  for (uint32_t id = 0; id < app.branches.size(); ++id) {
    const st::BranchPoint& b = app.branches[id];
    if (!wanted.count(b.loc.file) || b.decision == st::kNoBranch) continue;
    decisions[b.decision].push_back(id);
  }
  std::map<uint32_t, FileCoverage> by_file;
  auto add_line = [](FileCoverage& fc, st::SourceLoc loc, uint64_t n) {
    if (!loc.valid()) return;
    auto [it, fresh] = fc.lines.emplace(loc.line, n);
    if (!fresh) it->second = std::max(it->second, n);  // each contribution is a lower bound
  };
  for (const auto& [first, arms] : decisions) {
    const st::BranchPoint& head = app.branches[first];
    FileCoverage& fc = by_file[head.loc.file];
    std::vector<uint64_t> n;
    for (uint32_t id : arms) n.push_back(count(id));
    const bool repeat = head.kind == "REPEAT";
    const bool complete = repeat || app.branches[arms.back()].kind == "ELSE";
    const bool any = std::any_of(n.begin(), n.end(), [](uint64_t v) { return v > 0; });
    const bool not_run = (head.parent != st::kNoBranch && count(head.parent) == 0) || (complete && !any);
    const st::SourceLoc stmt = head.stmt.valid() ? head.stmt : head.loc;
    add_line(fc, stmt, any ? *std::max_element(n.begin(), n.end()) : 0);
    for (size_t j = 0; j < arms.size(); ++j) {
      const st::BranchPoint& b = app.branches[arms[j]];
      if (b.kind == "ELSIF") add_line(fc, b.loc, *std::max_element(n.begin() + static_cast<std::ptrdiff_t>(j), n.end()));
      else if (b.kind == "ELSE" || b.kind == "CASE") add_line(fc, b.loc, n[j]);
      add_line(fc, b.body, n[j]);
    }
    if (repeat) continue;
    CoverageDecision d;
    d.line = stmt.line;
    for (uint64_t v : n) d.arms.push_back(not_run ? std::nullopt : std::optional<uint64_t>(v));
    fc.decisions.push_back(std::move(d));
  }
  std::vector<FileCoverage> out;
  for (auto& [file, fc] : by_file) {
    std::error_code ec;
    std::filesystem::path p = std::filesystem::absolute(app.file_paths[file], ec);
    fc.path = ec ? app.file_paths[file] : p.lexically_normal().string();
    std::stable_sort(fc.decisions.begin(), fc.decisions.end(),
                     [](const CoverageDecision& a, const CoverageDecision& b) { return a.line < b.line; });
    for (size_t i = 0; i < fc.decisions.size(); ++i)
      fc.decisions[i].block = i > 0 && fc.decisions[i - 1].line == fc.decisions[i].line ? fc.decisions[i - 1].block + 1 : 0;
    out.push_back(std::move(fc));
  }
  std::sort(out.begin(), out.end(), [](const FileCoverage& a, const FileCoverage& b) { return a.path < b.path; });
  return out;
}

std::vector<uint32_t> coverage_files(const st::Build& b) {
  std::set<uint32_t> test_files;
  for (const auto& t : b.tests) test_files.insert(t->file);
  std::vector<uint32_t> out;
  for (const auto& u : b.units) {
    const st::SourceFile& f = b.sm.file(u->file);
    if (st::is_library_path(f.path) || f.library || f.path.empty() || f.path[0] == '<' || !f.origins.empty()) continue;
    if (test_files.count(u->file) || std::find(out.begin(), out.end(), u->file) != out.end()) continue;
    out.push_back(u->file);
  }
  return out;
}

std::string lcov_tracefile(const std::vector<FileCoverage>& files, const std::string& test_name) {
  std::string tn = test_name;
  for (char& c : tn)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') c = '_';
  std::string out;
  for (const auto& f : files) {
    out += "TN:" + tn + "\n";
    out += "SF:" + f.path + "\n";
    for (const auto& d : f.decisions)
      for (size_t j = 0; j < d.arms.size(); ++j)
        out += fmt::format("BRDA:{},{},{},{}\n", d.line, d.block, j, d.arms[j] ? std::to_string(*d.arms[j]) : "-");
    out += fmt::format("BRF:{}\nBRH:{}\n", f.branches(), f.branches_taken());
    for (const auto& [line, hits] : f.lines) out += fmt::format("DA:{},{}\n", line, hits);
    out += fmt::format("LF:{}\nLH:{}\n", f.lines.size(), f.lines_hit());
    out += "end_of_record\n";
  }
  return out;
}

namespace {

std::string rate(size_t part, size_t whole) { return whole ? fmt::format("{:.4f}", static_cast<double>(part) / whole) : "1"; }

}  // namespace

std::string cobertura_xml(const std::vector<FileCoverage>& files, int64_t timestamp_ms) {
  // The sources root: the longest folder all files lie in; file names are relative to it.
  std::filesystem::path root;
  for (const auto& f : files) {
    std::filesystem::path dir = std::filesystem::path(f.path).parent_path();
    if (root.empty()) {
      root = dir;
      continue;
    }
    std::filesystem::path common;
    for (auto a = root.begin(), b = dir.begin(); a != root.end() && b != dir.end() && *a == *b; ++a, ++b) common /= *a;
    root = common;
  }
  size_t lines = 0, lines_hit = 0, branches = 0, taken = 0;
  for (const auto& f : files) {
    lines += f.lines.size();
    lines_hit += f.lines_hit();
    branches += f.branches();
    taken += f.branches_taken();
  }
  std::string out = "<?xml version=\"1.0\" ?>\n"
                    "<!DOCTYPE coverage SYSTEM \"http://cobertura.sourceforge.net/xml/coverage-04.dtd\">\n";
  out += fmt::format(
      "<coverage line-rate=\"{}\" branch-rate=\"{}\" lines-covered=\"{}\" lines-valid=\"{}\" branches-covered=\"{}\" "
      "branches-valid=\"{}\" complexity=\"0\" version=\"plcfi\" timestamp=\"{}\">\n",
      rate(lines_hit, lines), rate(taken, branches), lines_hit, lines, taken, branches, timestamp_ms);
  out += "  <sources>\n    <source>" + xml_escape(root.string()) + "</source>\n  </sources>\n  <packages>\n";
  // Packages: the files' folders below the root, in path order (files come sorted).
  std::map<std::string, std::vector<const FileCoverage*>> packages;
  for (const auto& f : files) {
    std::string rel = std::filesystem::path(f.path).lexically_relative(root).parent_path().generic_string();
    packages[rel.empty() ? "." : rel].push_back(&f);
  }
  for (const auto& [pkg, members] : packages) {
    size_t pl = 0, plh = 0, pb = 0, pbt = 0;
    for (const FileCoverage* f : members) {
      pl += f->lines.size();
      plh += f->lines_hit();
      pb += f->branches();
      pbt += f->branches_taken();
    }
    std::string pkg_name = pkg;
    std::replace(pkg_name.begin(), pkg_name.end(), '/', '.');
    out += fmt::format("    <package name=\"{}\" line-rate=\"{}\" branch-rate=\"{}\" complexity=\"0\">\n      <classes>\n",
                       xml_escape(pkg_name), rate(plh, pl), rate(pbt, pb));
    for (const FileCoverage* f : members) {
      const std::filesystem::path rel = std::filesystem::path(f->path).lexically_relative(root);
      out += fmt::format(
          "        <class name=\"{}\" filename=\"{}\" line-rate=\"{}\" branch-rate=\"{}\" complexity=\"0\">\n"
          "          <methods/>\n          <lines>\n",
          xml_escape(rel.stem().string()), xml_escape(rel.generic_string()), rate(f->lines_hit(), f->lines.size()),
          rate(f->branches_taken(), f->branches()));
      for (const auto& [line, hits] : f->lines) {
        size_t n = 0, t = 0;
        for (const auto& d : f->decisions)
          if (d.line == line)
            for (const auto& a : d.arms) {
              ++n;
              t += a && *a > 0;
            }
        if (n == 0) {
          out += fmt::format("            <line number=\"{}\" hits=\"{}\" branch=\"false\"/>\n", line, hits);
          continue;
        }
        out += fmt::format(
            "            <line number=\"{}\" hits=\"{}\" branch=\"true\" condition-coverage=\"{}% ({}/{})\"/>\n", line,
            hits, t * 100 / n, t, n);
      }
      out += "          </lines>\n        </class>\n";
    }
    out += "      </classes>\n    </package>\n";
  }
  out += "  </packages>\n</coverage>\n";
  return out;
}

int64_t coverage_timestamp_ms() {
  if (const char* epoch = std::getenv("SOURCE_DATE_EPOCH")) {
    char* end = nullptr;
    errno = 0;
    long long s = std::strtoll(epoch, &end, 10);
    if (errno == 0 && end != epoch && *end == '\0' && s >= 0) return static_cast<int64_t>(s) * 1000;
  }
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

bool write_coverage_file(const std::string& path, const std::string& text, std::string* err) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) {
      *err = path + ": cannot write (" + std::strerror(errno) + ")";
      return false;
    }
    f << text;
    if (!f.flush()) {
      *err = path + ": write failed";
      std::remove(tmp.c_str());
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    *err = path + ": cannot write (" + std::strerror(errno) + ")";
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

}  // namespace plcfi::report
