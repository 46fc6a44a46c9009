// CSV and VCD trace readers and the trace program generator.
#include "trace_reader.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <sstream>

namespace plcfi::monitor {

namespace {

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur += c;
    }
  }
  out.push_back(cur);
  for (auto& s : out) {
    size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
    s = b == std::string::npos ? "" : s.substr(b, e - b + 1);
  }
  return out;
}

bool parse_number(const std::string& s, double* v) {
  if (s == "TRUE" || s == "true") {
    *v = 1;
    return true;
  }
  if (s == "FALSE" || s == "false") {
    *v = 0;
    return true;
  }
  if (s.empty()) return false;
  char* end = nullptr;
  *v = std::strtod(s.c_str(), &end);
  return end && *end == 0 && std::isfinite(*v);
}

class CsvReader final : public TraceReader {
 public:
  bool init(const std::string& path, int64_t cycle_ns, std::string* err) {
    path_ = path;
    cycle_ns_ = cycle_ns;
    in_.open(path);
    if (!in_) {
      *err = path + ": cannot open";
      return false;
    }
    std::string header;
    if (!std::getline(in_, header)) {
      *err = path + ":1: empty trace (a header line 'time,var,...' is expected)";
      return false;
    }
    auto names = split_csv(header);
    has_time_ = !names.empty() && (names[0] == "time" || names[0] == "t");
    for (size_t i = has_time_ ? 1 : 0; i < names.size(); ++i) {
      if (names[i].empty()) {
        *err = path + ":1: column " + std::to_string(i + 1) + " has no name";
        return false;
      }
      columns_.push_back(TraceColumn{names[i], TraceColumn::Kind::Bool});
    }
    if (columns_.empty()) {
      *err = path + ":1: no variable columns";
      return false;
    }
    // First pass: the kind of each column (BOOL when only 0/1, integer, else real).
    std::string line;
    size_t lineno = 1;
    while (std::getline(in_, line)) {
      ++lineno;
      if (line.empty() || line == "\r") continue;
      auto cells = split_csv(line);
      if (cells.size() != columns_.size() + (has_time_ ? 1 : 0)) {
        *err = path + ":" + std::to_string(lineno) + ": " + std::to_string(cells.size()) + " fields, the header has " +
               std::to_string(columns_.size() + (has_time_ ? 1 : 0));
        return false;
      }
      for (size_t c = 0; c < columns_.size(); ++c) {
        const std::string& cell = cells[c + (has_time_ ? 1 : 0)];
        double v;
        if (!parse_number(cell, &v)) {
          *err = path + ":" + std::to_string(lineno) + ": '" + cell + "' in column " + columns_[c].name + " is not a number";
          return false;
        }
        auto& k = columns_[c].kind;
        if (v != std::floor(v)) k = TraceColumn::Kind::Real;
        else if (k == TraceColumn::Kind::Bool && v != 0 && v != 1) k = TraceColumn::Kind::Int;
      }
    }
    in_.clear();
    in_.seekg(0);
    std::getline(in_, line);
    line_ = 1;
    return true;
  }

  bool next(int64_t* t, std::vector<double>* values, std::string* err) override {
    std::string line;
    while (std::getline(in_, line)) {
      ++line_;
      if (line.empty() || line == "\r") continue;
      auto cells = split_csv(line);
      values->resize(columns_.size());
      size_t off = has_time_ ? 1 : 0;
      for (size_t c = 0; c < columns_.size(); ++c) parse_number(cells[c + off], &(*values)[c]);
      if (has_time_) {
        double sec;
        if (!parse_number(cells[0], &sec)) {
          *err = path_ + ":" + std::to_string(line_) + ": time '" + cells[0] + "' is not a number of seconds";
          return false;
        }
        *t = static_cast<int64_t>(std::llround(sec * 1e9));
      } else {
        *t = static_cast<int64_t>(state_) * cycle_ns_;
      }
      ++state_;
      return true;
    }
    return false;
  }

 private:
  std::ifstream in_;
  std::string path_;
  int64_t cycle_ns_ = 0;
  size_t line_ = 0;
  uint64_t state_ = 0;
};

// VCD: header ($scope/$var/$upscope), then #time and value changes.
class VcdReader final : public TraceReader {
 public:
  bool init(const std::string& path, int64_t cycle_ns, std::string* err) {
    path_ = path;
    cycle_ns_ = cycle_ns;
    in_.open(path);
    if (!in_) {
      *err = path + ": cannot open";
      return false;
    }
    has_time_ = true;
    std::vector<std::string> scopes;
    std::string tok;
    while (word(&tok)) {
      if (tok == "$scope") {
        std::string kind, name;
        word(&kind);
        word(&name);
        scopes.push_back(name);
        skip_end();
      } else if (tok == "$upscope") {
        if (!scopes.empty()) scopes.pop_back();
        skip_end();
      } else if (tok == "$var") {
        std::string kind, width, id, name;
        word(&kind);
        word(&width);
        word(&id);
        word(&name);
        std::string full;
        for (const auto& s : scopes) full += s + ".";
        full += name;
        TraceColumn col{full, TraceColumn::Kind::Int};
        if (kind == "real") col.kind = TraceColumn::Kind::Real;
        else if (width == "1") col.kind = TraceColumn::Kind::Bool;
        ids_[id] = columns_.size();
        columns_.push_back(col);
        widths_.push_back(static_cast<size_t>(std::strtoul(width.c_str(), nullptr, 10)));
        signed_.push_back(kind == "integer");
        skip_end();
      } else if (tok == "$timescale") {
        std::string ts;
        word(&ts);
        std::string unit = ts;
        int64_t mult = 1;
        size_t k = 0;
        while (k < ts.size() && std::isdigit(static_cast<unsigned char>(ts[k]))) ++k;
        if (k > 0) mult = std::stoll(ts.substr(0, k));
        unit = ts.substr(k);
        if (unit.empty()) word(&unit);
        int64_t u = unit == "s" ? 1'000'000'000 : unit == "ms" ? 1'000'000 : unit == "us" ? 1'000 : unit == "ns" ? 1 : 0;
        if (u == 0) {
          *err = path + ":" + std::to_string(line_) + ": unsupported $timescale '" + ts + "'";
          return false;
        }
        timescale_ = mult * u;
        skip_end();
      } else if (tok == "$enddefinitions") {
        skip_end();
        break;
      } else if (!tok.empty() && tok[0] == '$') {
        skip_end();
      } else {
        *err = path + ":" + std::to_string(line_) + ": unexpected '" + tok + "' in the VCD header";
        return false;
      }
    }
    if (columns_.empty()) {
      *err = path + ": no $var in the VCD header";
      return false;
    }
    cur_.assign(columns_.size(), 0.0);
    return true;
  }

  bool next(int64_t* t, std::vector<double>* values, std::string* err) override {
    // Resampled: states every cycle_ns, each holding the values of the last change.
    if (cycle_ns_ > 0) {
      if (!started_) {
        if (!advance(err)) return false;
        started_ = true;
        sample_t_ = pending_t_;
      }
      while (!ended_ && next_change_t_ <= sample_t_) {
        if (!advance(err) && !err->empty()) return false;
      }
      if (ended_ && sample_t_ > last_t_) return false;
      *t = sample_t_;
      *values = cur_;
      sample_t_ += cycle_ns_;
      return true;
    }
    if (!advance(err)) return false;
    *t = pending_t_;
    *values = cur_;
    return true;
  }

 private:
  bool word(std::string* out) {
    out->clear();
    int c;
    while ((c = in_.get()) != EOF && std::isspace(c))
      if (c == '\n') ++line_;
    if (c == EOF) return false;
    *out += static_cast<char>(c);
    while ((c = in_.peek()) != EOF && !std::isspace(c)) *out += static_cast<char>(in_.get());
    return true;
  }
  void skip_end() {
    std::string w;
    while (word(&w) && w != "$end") {
    }
  }
  // Applies the changes of one time stamp to cur_; pending_t_ is that time. For the
  // resampled mode, next_change_t_ is the following time stamp.
  bool advance(std::string* err) {
    std::string w;
    bool have_time = false;
    for (;;) {
      std::streampos pos = in_.tellg();
      size_t line_before = line_;
      if (!word(&w)) {
        ended_ = true;
        next_change_t_ = INT64_MAX;
        return have_time;
      }
      if (w[0] == '#') {
        int64_t tv = std::strtoll(w.c_str() + 1, nullptr, 10) * timescale_;
        if (have_time) {
          in_.seekg(pos);
          line_ = line_before;
          next_change_t_ = tv;
          return true;
        }
        have_time = true;
        pending_t_ = tv;
        last_t_ = tv;
        continue;
      }
      if (w == "$dumpvars" || w == "$end" || w == "$dumpall" || w == "$dumpon" || w == "$dumpoff") continue;
      if (w == "$comment") {
        skip_end();
        continue;
      }
      char k = w[0];
      std::string value, id;
      if (k == 'b' || k == 'B' || k == 'r' || k == 'R') {
        value = w.substr(1);
        word(&id);
      } else if (k == '0' || k == '1' || k == 'x' || k == 'X' || k == 'z' || k == 'Z') {
        value = std::string(1, k);
        id = w.substr(1);
      } else {
        *err = path_ + ":" + std::to_string(line_) + ": unexpected '" + w + "' in the VCD body";
        return false;
      }
      auto it = ids_.find(id);
      if (it == ids_.end()) {
        *err = path_ + ":" + std::to_string(line_) + ": value change for undeclared identifier '" + id + "'";
        return false;
      }
      double v = 0;
      if (k == 'r' || k == 'R') {
        v = std::strtod(value.c_str(), nullptr);
      } else {
        uint64_t bits = 0;
        for (char ch : value) bits = (bits << 1) | (ch == '1' ? 1u : 0u);
        // A shorter value is zero-extended (VCD); a signed "integer" that fills its width
        // with a leading 1 is negative (two's complement).
        size_t width = widths_[it->second];
        if (signed_[it->second] && value.size() == width && value[0] == '1' && width > 1 && width < 64)
          v = static_cast<double>(static_cast<int64_t>(bits) - (static_cast<int64_t>(1) << width));
        else if (signed_[it->second] && value.size() == 64 && width == 64)
          v = static_cast<double>(static_cast<int64_t>(bits));
        else
          v = static_cast<double>(bits);
      }
      cur_[it->second] = v;
      if (!have_time) {
        *err = path_ + ":" + std::to_string(line_) + ": value change before the first #time";
        return false;
      }
    }
  }

  std::ifstream in_;
  std::string path_;
  int64_t cycle_ns_ = 0, timescale_ = 1;
  size_t line_ = 1;
  std::map<std::string, size_t> ids_;
  std::vector<size_t> widths_;
  std::vector<bool> signed_;
  std::vector<double> cur_;
  int64_t pending_t_ = 0, next_change_t_ = 0, sample_t_ = 0, last_t_ = 0;
  bool started_ = false, ended_ = false;
};

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

}  // namespace

std::unique_ptr<TraceReader> TraceReader::open(const std::string& path, int64_t cycle_ns, std::string* err) {
  bool vcd = path.size() > 4 && path.substr(path.size() - 4) == ".vcd";
  if (vcd) {
    auto r = std::make_unique<VcdReader>();
    if (!r->init(path, cycle_ns, err)) return nullptr;
    return r;
  }
  auto r = std::make_unique<CsvReader>();
  if (!r->init(path, cycle_ns, err)) return nullptr;
  return r;
}

bool trace_program(const std::vector<TraceColumn>& cols, std::string* source, std::string* err) {
  // A tree of names: leaves are variables, inner nodes programs (top) or structs.
  struct Node {
    std::map<std::string, Node> children;
    const TraceColumn* leaf = nullptr;
  };
  Node root;
  for (const auto& c : cols) {
    if (!c.name.empty() && c.name[0] == '%') continue;  // image addresses need no declaration
    Node* n = &root;
    std::string part;
    std::vector<std::string> parts;
    for (char ch : c.name + ".") {
      if (ch == '.') {
        parts.push_back(part);
        part.clear();
      } else {
        part += ch;
      }
    }
    for (size_t i = 0; i < parts.size(); ++i) {
      if (!is_identifier(parts[i])) {
        *err = "trace column '" + c.name + "' is not an ST name (letters, digits, '_', dots between names)";
        return false;
      }
      if (n->leaf) {
        *err = "trace column '" + c.name + "' is inside the column of a plain variable";
        return false;
      }
      n = &n->children[parts[i]];
    }
    if (n->leaf || !n->children.empty()) {
      *err = "trace column '" + c.name + "' appears twice or also has members";
      return false;
    }
    n->leaf = &c;
  }
  auto type_of = [](const TraceColumn& c) {
    return c.kind == TraceColumn::Kind::Bool ? "BOOL" : c.kind == TraceColumn::Kind::Int ? "LINT" : "LREAL";
  };
  std::string types, globals, programs;
  int struct_id = 0;
  std::function<std::string(const Node&)> struct_of = [&](const Node& n) -> std::string {
    std::string name = "__TraceStruct" + std::to_string(++struct_id);
    std::string body;
    for (const auto& [k, child] : n.children)
      body += "  " + k + " : " + (child.leaf ? std::string(type_of(*child.leaf)) : struct_of(child)) + ";\n";
    types += "TYPE " + name + " : STRUCT\n" + body + "END_STRUCT; END_TYPE\n";
    return name;
  };
  for (const auto& [k, child] : root.children) {
    if (child.leaf) {
      globals += "  " + k + " : " + type_of(*child.leaf) + ";\n";
      continue;
    }
    std::string vars;
    for (const auto& [m, gc] : child.children)
      vars += "  " + m + " : " + (gc.leaf ? std::string(type_of(*gc.leaf)) : struct_of(gc)) + ";\n";
    programs += "PROGRAM " + k + "\nVAR\n" + vars + "END_VAR\nEND_PROGRAM\n";
  }
  *source = types;
  if (!globals.empty()) *source += "VAR_GLOBAL\n" + globals + "END_VAR\n";
  *source += programs;
  return true;
}

}  // namespace plcfi::monitor
