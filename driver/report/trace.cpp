// VCD and CSV trace writers.
#include "trace.hpp"

#include <cstring>
#include <map>

#include <fmt/format.h>

namespace plcfi::report {

namespace {

bool traceable(const st::VarHandle& h, std::string* err) {
  if (h.is_bit || h.type->is_elementary()) return true;
  *err = "cannot trace '" + h.path + "' (" + h.type->name + "): name an elementary member or element";
  return false;
}

// TIME, LTIME, DATE, TIME_OF_DAY, DATE_AND_TIME: written to CSV as literals.
bool is_time_like(st::TypeKind k) {
  return k == st::TypeKind::Time || k == st::TypeKind::LTime || k == st::TypeKind::Date ||
         k == st::TypeKind::TimeOfDay || k == st::TypeKind::DateTime;
}

class FileSink {
 public:
  bool open(const std::string& path, std::string* err) {
    path_ = path;
    f_ = std::fopen(path.c_str(), "wb");
    if (!f_) {
      *err = path + ": cannot write (" + std::strerror(errno) + ")";
      return false;
    }
    return true;
  }
  ~FileSink() {
    if (f_) std::fclose(f_);
  }
  void put(const std::string& s) {
    buf_ += s;
    if (buf_.size() > (1u << 16)) flush();
  }
  void flush() {
    if (f_ && !buf_.empty()) {
      if (std::fwrite(buf_.data(), 1, buf_.size(), f_) != buf_.size()) failed_ = true;
      buf_.clear();
    }
  }
  bool close(std::string* err) {
    flush();
    if (f_ && std::fclose(f_) != 0) failed_ = true;
    f_ = nullptr;
    if (failed_) *err = path_ + ": write failed";
    return !failed_;
  }

 private:
  FILE* f_ = nullptr;
  std::string buf_, path_;
  bool failed_ = false;
};

enum class VcdKind { Wire, Integer, Real };

class VcdWriter final : public TraceWriter {
 public:
  bool init(const std::string& path, const std::vector<st::VarHandle>& vars, std::string* err, const std::string& comment) {
    for (const auto& v : vars)
      if (!traceable(v, err)) return false;
    if (!sink_.open(path, err)) return false;
    vars_ = vars;
    sink_.put("$version plcfi $end\n");
    if (!comment.empty()) {
      // "$end" inside the text would end the comment early: its '$' becomes 'S'.
      std::string c;
      for (size_t i = 0; i < comment.size(); ++i)
        c.push_back(comment[i] == '$' && comment.compare(i, 4, "$end") == 0 ? 'S' : comment[i]);
      sink_.put("$comment ");
      sink_.put(c);
      sink_.put(" $end\n");
    }
    sink_.put("$timescale 1ns $end\n");
    // Hierarchy from the dotted paths: Main.cyl.Valve -> scope Main, scope cyl, var Valve.
    std::vector<std::string> open_scopes;
    for (size_t i = 0; i < vars_.size(); ++i) {
      const auto& h = vars_[i];
      std::vector<std::string> parts;
      std::string cur;
      for (char c : h.path) {
        if (c == '.') {
          parts.push_back(cur);
          cur.clear();
        } else {
          cur += c;
        }
      }
      std::string leaf = cur;
      size_t common = 0;
      while (common < open_scopes.size() && common < parts.size() && open_scopes[common] == parts[common]) ++common;
      while (open_scopes.size() > common) {
        sink_.put("$upscope $end\n");
        open_scopes.pop_back();
      }
      for (size_t k = common; k < parts.size(); ++k) {
        sink_.put("$scope module " + parts[k] + " $end\n");
        open_scopes.push_back(parts[k]);
      }
      ids_.push_back(make_id(i));
      VcdKind kind = (h.is_bit || h.type->kind == st::TypeKind::Bool) ? VcdKind::Wire
                     : h.type->is_real()                                 ? VcdKind::Real
                                                                         : VcdKind::Integer;
      kinds_.push_back(kind);
      uint32_t width = kind == VcdKind::Wire ? 1 : kind == VcdKind::Real ? 64 : h.type->size * 8;
      widths_.push_back(width);
      // Signed integers are VCD "integer"; unsigned ones and bit strings "reg".
      const char* vtype = kind == VcdKind::Wire ? "wire" : kind == VcdKind::Real ? "real"
                          : (h.type->is_signed() || h.type->is_time_like() || h.type->kind == st::TypeKind::Enum) ? "integer" : "reg";
      sink_.put(fmt::format("$var {} {} {} {} $end\n", vtype, width, ids_.back(), leaf));
    }
    while (!open_scopes.empty()) {
      sink_.put("$upscope $end\n");
      open_scopes.pop_back();
    }
    sink_.put("$enddefinitions $end\n");
    last_.assign(vars_.size(), std::string());
    return true;
  }

  void sample(int64_t t, const st::Machine& m) override {
    bool stamped = false;
    for (size_t i = 0; i < vars_.size(); ++i) {
      std::string v = value(i, m);
      if (!first_ && v == last_[i]) continue;
      if (!stamped) {
        sink_.put(fmt::format("#{}\n", t));
        if (first_) sink_.put("$dumpvars\n");
        stamped = true;
      }
      sink_.put(v);
      last_[i] = std::move(v);
    }
    if (first_ && stamped) sink_.put("$end\n");
    first_ = false;
    last_t_ = t;
  }

  bool close(std::string* err) override { return sink_.close(err); }

 private:
  static std::string make_id(size_t i) {
    std::string id;
    do {
      id += static_cast<char>(33 + i % 94);
      i /= 94;
    } while (i);
    return id;
  }
  std::string value(size_t i, const st::Machine& m) const {
    const auto& h = vars_[i];
    switch (kinds_[i]) {
      case VcdKind::Wire: return std::string(st::read_bool(m, h) ? "1" : "0") + ids_[i] + "\n";
      case VcdKind::Real: return fmt::format("r{} {}\n", st::read_real(m, h), ids_[i]);
      case VcdKind::Integer: {
        auto bits = static_cast<uint64_t>(st::read_int(m, h));
        uint32_t w = widths_[i];
        if (w < 64) bits &= (uint64_t(1) << w) - 1;
        std::string b;
        for (int k = static_cast<int>(w) - 1; k >= 0; --k) {
          bool one = (bits >> k) & 1u;
          if (b.empty() && !one && k > 0) continue;  // leading zeros are implied
          b += one ? '1' : '0';
        }
        return "b" + b + " " + ids_[i] + "\n";
      }
    }
    return "";
  }

  FileSink sink_;
  std::vector<st::VarHandle> vars_;
  std::vector<std::string> ids_, last_;
  std::vector<VcdKind> kinds_;
  std::vector<uint32_t> widths_;
  bool first_ = true;
  int64_t last_t_ = 0;
};

class CsvWriter final : public TraceWriter {
 public:
  bool init(const std::string& path, const std::vector<st::VarHandle>& vars, std::string* err) {
    for (const auto& v : vars)
      if (!traceable(v, err)) return false;
    if (!sink_.open(path, err)) return false;
    vars_ = vars;
    std::string header = "time";
    for (const auto& v : vars_) header += "," + v.path;
    sink_.put(header + "\n");
    return true;
  }
  void sample(int64_t t, const st::Machine& m) override {
    std::string row = fmt::format("{}.{:09}", t / 1'000'000'000, t % 1'000'000'000);
    while (row.back() == '0') row.pop_back();
    if (row.back() == '.') row.pop_back();
    for (const auto& h : vars_) {
      row += ',';
      if (h.is_bit || h.type->kind == st::TypeKind::Bool) row += st::read_bool(m, h) ? '1' : '0';
      else if (is_time_like(h.type->kind)) row += st::format(m, h);  // T#1s500ms, D#2024-03-01, ... as --print
      else if (h.type->is_real()) row += fmt::format("{}", st::read_real(m, h));
      else if (h.type->storage() == st::Storage::U64) row += std::to_string(static_cast<uint64_t>(st::read_int(m, h)));
      else row += std::to_string(st::read_int(m, h));
    }
    sink_.put(row + "\n");
  }
  bool close(std::string* err) override { return sink_.close(err); }

 private:
  FileSink sink_;
  std::vector<st::VarHandle> vars_;
};

}  // namespace

std::unique_ptr<TraceWriter> open_vcd(const std::string& path, const std::vector<st::VarHandle>& vars, std::string* err,
                                      const std::string& comment) {
  auto w = std::make_unique<VcdWriter>();
  if (!w->init(path, vars, err, comment)) return nullptr;
  return w;
}

std::unique_ptr<TraceWriter> open_csv(const std::string& path, const std::vector<st::VarHandle>& vars, std::string* err) {
  auto w = std::make_unique<CsvWriter>();
  if (!w->init(path, vars, err)) return nullptr;
  return w;
}

}  // namespace plcfi::report
