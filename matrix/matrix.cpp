// Matrix files: parsing (TOML, read by toml++) and deterministic expansion.
#include "matrix/matrix.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include <toml++/toml.h>

#include "core/format.hpp"
#include "harness/integrator.hpp"
#include "harness/stability.hpp"
#include "harness/tune.hpp"
#include "io/hash.hpp"

namespace cstab {

std::string SourceLocation::str() const {
  return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  // Bounded: a device (/dev/zero) or a runaway file is refused, not read
  // until memory runs out.
  std::string text;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, size_t(in.gcount()));
    if (text.size() > kMaxInputFileBytes)
      throw UsageError(path + ": larger than " + std::to_string(kMaxInputFileBytes >> 20) +
                       " MiB: not a file cstab wrote or reads");
  }
  if (in.bad()) throw std::runtime_error("cannot read " + path);
  return text;
}

// ===========================================================================
// Parser: toml++ reads the TOML; this maps its tree onto MatrixFile (sections
// and entries in file order, dotted keys joined, numbers with their source
// text) and refuses what a matrix file cannot hold.

namespace {

bool is_bare_key_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

bool is_utf8_continuation(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }

// The source text addressed by toml++ positions: 1-based lines, columns in
// code points, a UTF-8 byte order mark at the start not counted. Lookups are
// O(1) on ASCII lines and resume from the last one on others (toml++ asks in
// file order), so a line of 100 000 values stays linear.
class SourceText {
 public:
  SourceText(const std::string& text, const std::string& file) : s_(text), file_(file) {
    const size_t start = s_.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
    line_starts_.push_back(start);
    ascii_.push_back(true);
    for (size_t i = start; i < s_.size(); ++i) {
      if (s_[i] == '\n') {
        line_starts_.push_back(i + 1);
        ascii_.push_back(true);
      } else if (static_cast<unsigned char>(s_[i]) >= 0x80) {
        ascii_.back() = false;
      }
    }
  }

  SourceLocation at(const toml::source_position& p) const {
    return {file_, std::max(int(p.line), 1), std::max(int(p.column), 1)};
  }

  // Byte offset of a position (the end of its line if the column is beyond
  // it, the end of the text if the line is).
  size_t offset(const toml::source_position& p) const {
    if (p.line < 1 || p.line > line_starts_.size()) return s_.size();
    const size_t start = line_starts_[p.line - 1];
    const size_t end = p.line < line_starts_.size() ? line_starts_[p.line] - 1 : s_.size();
    const size_t column = std::max<size_t>(p.column, 1);
    if (ascii_[p.line - 1]) return std::min(start + column - 1, end);
    if (memo_.line != p.line || memo_.column > column) memo_ = {p.line, 1, start};
    size_t c = memo_.column, i = memo_.offset;
    for (; c < column && i < end; ++c)
      for (++i; i < end && is_utf8_continuation(s_[i]);) ++i;
    memo_ = {p.line, c, i};
    return i;
  }

  std::string slice(const toml::source_region& r) const {
    const size_t b = offset(r.begin), e = offset(r.end);
    return e > b ? s_.substr(b, e - b) : std::string();
  }

  char char_at(const toml::source_position& p) const {
    const size_t i = offset(p);
    return i < s_.size() ? s_[i] : '\0';
  }

  // Where the key whose last part starts at `leaf` begins: back over the
  // dotted key (parts, dots, blanks) to the line start, '{' or ','.
  SourceLocation key_start(const toml::source_position& leaf) const {
    if (leaf.line < 1 || leaf.line > line_starts_.size()) return at(leaf);
    const size_t line_start = line_starts_[leaf.line - 1];
    const size_t leaf_at = offset(leaf);
    size_t j = leaf_at;
    while (j > line_start) {
      const char c = s_[j - 1];
      if (is_bare_key_char(c) || c == '.' || c == ' ' || c == '\t') {
        --j;
      } else if ((c == '"' || c == '\'') && j - 1 > line_start) {  // a quoted part
        const size_t open = s_.rfind(c, j - 2);
        if (open == std::string::npos || open < line_start) break;
        j = open;
      } else {
        break;
      }
    }
    while (j < s_.size() && (s_[j] == ' ' || s_[j] == '\t')) ++j;
    // Only blanks, key parts and dots were passed: the column is the leaf's
    // less the code points in between.
    size_t between = 0;
    for (size_t i = j; i < leaf_at; ++i) between += !is_utf8_continuation(s_[i]);
    return {file_, int(leaf.line), int(leaf.column - between)};
  }

  // The word at a position (up to a blank, ',', ']', '}' or '#').
  std::string word_at(const toml::source_position& p) const {
    std::string w;
    for (size_t i = offset(p); i < s_.size() && w.size() < 40; ++i) {
      if (std::string_view(" \t\r\n,]}#").find(s_[i]) != std::string_view::npos) break;
      w += s_[i];
    }
    return w;
  }

 private:
  struct Memo {
    toml::source_index line = 0;
    size_t column = 1, offset = 0;  // `column` of `line` starts at byte `offset`
  };
  const std::string& s_;
  std::string file_;
  std::vector<size_t> line_starts_;
  std::vector<char> ascii_;  // per line: no byte >= 0x80 (columns are bytes)
  mutable Memo memo_;
};

// Children of a table in file order (toml++ keeps them sorted by key).
std::vector<std::pair<const toml::key*, const toml::node*>> in_file_order(const toml::table& t) {
  std::vector<std::pair<const toml::key*, const toml::node*>> out;
  for (const auto& [k, v] : t) out.emplace_back(&k, &v);
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    const auto &pa = a.first->source().begin, &pb = b.first->source().begin;
    return std::make_pair(pa.line, pa.column) < std::make_pair(pb.line, pb.column);
  });
  return out;
}

bool before(const SourceLocation& a, const SourceLocation& b) {
  return std::make_pair(a.line, a.column) < std::make_pair(b.line, b.column);
}

// toml++'s tree -> MatrixFile.
class TreeReader {
 public:
  explicit TreeReader(const SourceText& src) : src_(src) {}

  std::vector<MatrixSection> sections(const toml::table& root) const {
    std::vector<MatrixSection> out;
    for (const auto& [key, node] : in_file_order(root)) {
      const SourceLocation key_at = src_.at(key->source().begin);
      // Written as [name] or [[name]] (not a dotted key or an inline table).
      const bool header = src_.char_at(node->source().begin) == '[' &&
                          (node->is_table() || (node->is_array_of_tables() &&
                                                src_.char_at(node->as_array()->front().source().begin) == '['));
      if (key->str() == "defaults" && node->is_table()) {
        out.push_back(section("defaults", *node->as_table()));
      } else if (key->str() == "sweep" && node->is_array_of_tables()) {
        for (const toml::node& t : *node->as_array()) out.push_back(section("sweep", *t.as_table()));
      } else if (key->str() == "sweep" && header) {
        throw MatrixError(key_at, "a sweep is an array of tables: write [[sweep]]");
      } else if (key->str() == "defaults" && node->is_array_of_tables()) {
        throw MatrixError(key_at, "[defaults] is one table: write [defaults], not [[defaults]]");
      } else if (header) {
        throw MatrixError(key_at, "unknown section '" + std::string(key->str()) + "' (known: [defaults], [[sweep]])");
      } else {
        throw MatrixError(src_.key_start(key->source().begin),
                          "key outside a section: start the file with [defaults] or [[sweep]]");
      }
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const MatrixSection& a, const MatrixSection& b) { return before(a.where, b.where); });
    return out;
  }

 private:
  MatrixSection section(const std::string& kind, const toml::table& t) const {
    MatrixSection sec;
    sec.kind = kind;
    sec.where = src_.at(t.source().begin);
    add_entries(t, "", sec);
    std::stable_sort(sec.entries.begin(), sec.entries.end(),
                     [](const MatrixEntry& a, const MatrixEntry& b) { return before(a.where, b.where); });
    return sec;
  }

  // Every value under `t`, nested tables (dotted keys, sub-tables) walked.
  void add_entries(const toml::table& t, const std::string& prefix, MatrixSection& sec) const {
    for (const auto& [key, node] : in_file_order(t)) {
      const std::string part(key->str());
      const std::string full = prefix.empty() ? part : prefix + "." + part;
      if (part.empty() || !std::all_of(part.begin(), part.end(), is_bare_key_char))
        throw MatrixError(src_.at(key->source().begin),
                          "key '" + full + "': a key part is letters, digits, '_' and '-' only");
      if (const toml::table* sub = node->as_table()) {
        if (sub->empty()) throw MatrixError(src_.at(key->source().begin), "'" + full + "': empty table");
        add_entries(*sub, full, sec);
        continue;
      }
      MatrixEntry e;
      e.key = full;
      e.where = src_.key_start(key->source().begin);
      e.value = value(*node, full, false);
      sec.entries.push_back(std::move(e));
    }
  }

  MatrixValue value(const toml::node& n, const std::string& key, bool in_array) const {
    MatrixValue v;
    v.where = src_.at(n.source().begin);
    if (const auto* s = n.as_string()) {
      v.kind = MatrixValue::Kind::kString;
      v.text = s->get();
    } else if (n.is_integer() || n.is_floating_point()) {
      v.kind = MatrixValue::Kind::kNumber;
      v.text = src_.slice(n.source());
      v.number = n.is_integer() ? double(n.as_integer()->get()) : n.as_floating_point()->get();
      if (!std::isfinite(v.number)) throw MatrixError(v.where, "'" + v.text + "' is not a finite number");
    } else if (const auto* b = n.as_boolean()) {
      v.kind = MatrixValue::Kind::kBool;
      v.boolean = b->get();
    } else if (const auto* a = n.as_array()) {
      if (in_array) throw MatrixError(v.where, key + ": nested arrays are not supported");
      v.kind = MatrixValue::Kind::kArray;
      for (const toml::node& item : *a) v.items.push_back(value(item, key, true));
    } else if (n.is_table()) {
      throw MatrixError(v.where, key + ": a table is not a value here (arrays hold numbers, strings or true/false)");
    } else {
      throw MatrixError(v.where, key + ": dates and times are not values of a matrix file (strings are quoted)");
    }
    return v;
  }

  const SourceText& src_;
};

// Refuses, before toml++ 3.3.0 sees the text, what it mishandles:
// - it reaches __builtin_unreachable (undefined behaviour) when it asks
//   whether some non-ASCII characters are whitespace: outside strings and
//   comments, and first after a line-ending backslash in a """ string
//   (marzer/tomlplusplus issues 190 and 295). TOML allows non-ASCII only in
//   strings and comments: this refuses what toml++ would refuse anyway, plus
//   that one valid case;
// - it recurses once per part of a dotted key (a stack overflow at some
//   100 000 parts); a matrix key has at most three.
void refuse_what_toml_mishandles(const std::string& s, const std::string& file) {
  constexpr int kMaxDots = 64;  // in a row, outside strings and comments
  enum class In { kCode, kComment, kBasic, kLiteral, kMultiBasic, kMultiLiteral } in = In::kCode;
  int line = 1, column = 1, dots = 0;
  char prev = '\n';  // the character before, in code
  size_t i = s.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
  auto starts = [&](const char* t) { return s.compare(i, std::strlen(t), t) == 0; };
  auto advance = [&](size_t n) {
    for (; n > 0 && i < s.size(); --n, ++i) {
      if (s[i] == '\n') {
        ++line;
        column = 1;
      } else if (!is_utf8_continuation(s[i])) {
        ++column;
      }
    }
  };
  const auto refuse = [&](const std::string& what) { throw MatrixError({file, line, column}, what); };
  while (i < s.size()) {
    const char c = s[i];
    if (in == In::kCode) {
      if (static_cast<unsigned char>(c) >= 0x80)
        refuse("non-ASCII character outside a string or comment (TOML allows them only there)");
      if (c == '.' && ++dots > kMaxDots)
        refuse("more than " + std::to_string(kMaxDots) + " dots in a dotted key (a matrix key has at most three "
               "parts: param.METHOD.NAME)");
      if (!is_bare_key_char(c) && std::string_view(". \t\"'").find(c) == std::string_view::npos) dots = 0;
      // A quote starts a string where a value or a key may start; within a
      // bare word (`0xZ"..`) toml++ reads on to the next blank, ',' or ']'.
      const bool token_start = std::string_view("\n\r \t=[{,").find(prev) != std::string_view::npos;
      if (c == '#') in = In::kComment;
      if (c == '"' && token_start) in = starts("\"\"\"") ? (advance(2), In::kMultiBasic) : In::kBasic;
      if (c == '\'' && token_start) in = starts("\'\'\'") ? (advance(2), In::kMultiLiteral) : In::kLiteral;
      prev = c;
    } else if (c == '\n' && in != In::kMultiBasic && in != In::kMultiLiteral) {
      in = In::kCode;  // end of a comment (or of an unterminated string: toml++ says so)
      prev = c;
    } else if ((in == In::kBasic && c == '"') || (in == In::kLiteral && c == '\'')) {
      in = In::kCode;
      prev = c;
    } else if ((in == In::kMultiBasic && starts("\"\"\"")) || (in == In::kMultiLiteral && starts("\'\'\'"))) {
      advance(2);
      while (i + 1 < s.size() && s[i + 1] == c) advance(1);  // up to two quotes belong to the string
      in = In::kCode;
      prev = c;
    } else if ((in == In::kBasic || in == In::kMultiBasic) && c == '\\') {
      size_t j = i + 1;  // a line-ending backslash: blanks, newline, then whitespace is skipped
      while (in == In::kMultiBasic && j < s.size() && (s[j] == ' ' || s[j] == '\t' || s[j] == '\r')) ++j;
      if (in == In::kMultiBasic && j < s.size() && s[j] == '\n') {
        while (j < s.size() && std::string_view(" \t\r\n").find(s[j]) != std::string_view::npos) ++j;
        advance(j - i);
        if (i < s.size() && static_cast<unsigned char>(s[i]) >= 0x80)
          refuse("non-ASCII character first after a line-ending backslash: toml++ 3.3 cannot read it "
                 "(put an ASCII character before it)");
        continue;
      }
      advance(1);  // the escaped character is skipped below
    }
    advance(1);
  }
}

// toml++'s description of a syntax error, with a hint where it is terse.
std::string syntax_error_message(const toml::parse_error& e, const SourceText& src) {
  std::string what(e.description());
  const auto has = [&](const char* part) { return what.find(part) != std::string::npos; };
  const char at = src.char_at(e.source().begin);
  const std::string word = src.word_at(e.source().begin);
  if (has("could not determine value type") && !word.empty())  // a bare word
    return "'" + word + "' is not a number, true/false, array or string (strings are quoted: \"" + word + "\")";
  if (has("parsing string") && (at == '\n' || at == '\r' || at == '\0'))
    what += " (unterminated string: missing its closing quote on this line)";
  else if (has("parsing array") && has("end-of-file"))
    what += " (unterminated array: missing ']')";
  return what;
}

}  // namespace

MatrixFile parse_matrix(const std::string& text, const std::string& file_name) {
  MatrixFile out;
  out.name = file_name;
  out.text = text;
  const SourceText src(out.text, file_name);
  refuse_what_toml_mishandles(out.text, file_name);
  toml::table root;
  try {
    root = toml::parse(std::string_view(out.text), std::string_view(file_name));
  } catch (const toml::parse_error& e) {
    throw MatrixError(src.at(e.source().begin), syntax_error_message(e, src));
  }
  out.sections = TreeReader(src).sections(root);
  return out;
}

MatrixFile read_matrix_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw UsageError(path + ": is a folder, not a matrix file");
  std::string text;
  try {
    text = read_text_file(path);
  } catch (const UsageError&) {
    throw;  // too large
  } catch (const std::exception&) {
    throw UsageError(path + ": cannot read the matrix file");
  }
  return parse_matrix(text, path);
}

std::vector<std::string> matrix_plugins(const MatrixFile& file) {
  std::vector<std::string> paths;
  for (const auto& sec : file.sections) {
    if (sec.kind != "defaults") continue;
    for (const auto& e : sec.entries) {
      if (e.key != "plugins") continue;
      const bool array = e.value.kind == MatrixValue::Kind::kArray;
      const std::vector<MatrixValue> one{e.value};
      for (const MatrixValue& v : array ? e.value.items : one) {
        if (v.kind != MatrixValue::Kind::kString || v.text.empty())
          throw MatrixError(v.where, "'plugins': each entry is the path of a plugin file, as a string");
        paths.push_back(v.text);
      }
    }
  }
  return paths;
}

// ===========================================================================
// Expansion

namespace {

using Kind = MatrixValue::Kind;

const std::vector<std::string>& known_keys() {
  static const std::vector<std::string> keys = {
      "name", "problems", "methods", "formulations", "integrators", "step", "tol", "rtol", "atol",
      "t_end", "ref_time", "times", "sample_every", "blowup", "observe_every", "series", "keep_series", "repeats",
      "timeout", "repeat_if_under", "work_precision", "overlay", "optional", "perturb", "max_steps",
      "external", "external_name", "plugins", "tune"};
  return keys;
}

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  std::iota(prev.begin(), prev.end(), 0);
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string suggestion(const std::string& word, const std::vector<std::string>& known) {
  std::string best;
  size_t best_d = 3;
  for (const auto& k : known) {
    const size_t d = edit_distance(word, k);
    // "problem" -> "problems" and the like
    if (d < best_d || (k.rfind(word, 0) == 0 && d <= 2)) {
      best = k;
      best_d = d;
    }
  }
  return best.empty() ? "" : " (did you mean '" + best + "'?)";
}

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::kString: return "a string";
    case Kind::kNumber: return "a number";
    case Kind::kBool: return "true/false";
    default: return "an array";
  }
}

// A sweep's settings: its own entries over [defaults].
class Settings {
 public:
  Settings(const MatrixSection* defaults, const MatrixSection& sweep) : sweep_(sweep) {
    if (defaults)
      for (const auto& e : defaults->entries) values_[e.key] = &e;
    for (const auto& e : sweep.entries) values_[e.key] = &e;
  }

  const MatrixEntry* find(const std::string& key) const {
    auto it = values_.find(key);
    return it == values_.end() ? nullptr : it->second;
  }
  const SourceLocation& where() const { return sweep_.where; }

  // Every element (a scalar is a one-element list), all of kind `k`.
  std::vector<const MatrixValue*> list(const std::string& key, Kind k) const {
    std::vector<const MatrixValue*> out;
    const MatrixEntry* e = find(key);
    if (!e) return out;
    if (e->value.kind == Kind::kArray) {
      if (e->value.items.empty()) throw MatrixError(e->value.where, key + ": empty array");
      for (const auto& item : e->value.items) out.push_back(&item);
    } else {
      out.push_back(&e->value);
    }
    for (const auto* v : out)
      if (v->kind != k)
        throw MatrixError(v->where, key + ": expected " + std::string(kind_name(k)) + ", found " + kind_name(v->kind));
    return out;
  }
  const MatrixValue* scalar(const std::string& key, Kind k) const {
    const MatrixEntry* e = find(key);
    if (!e) return nullptr;
    if (e->value.kind != k)
      throw MatrixError(e->value.where, key + ": expected " + std::string(kind_name(k)) + ", found " +
                                            kind_name(e->value.kind));
    return &e->value;
  }
  double number(const std::string& key, double fallback) const {
    const MatrixValue* v = scalar(key, Kind::kNumber);
    return v ? v->number : fallback;
  }
  bool boolean(const std::string& key, bool fallback) const {
    const MatrixValue* v = scalar(key, Kind::kBool);
    return v ? v->boolean : fallback;
  }
  // "all" or a list of names.
  std::vector<const MatrixValue*> names(const std::string& key, bool* all) const {
    *all = false;
    const MatrixEntry* e = find(key);
    if (e && e->value.kind == Kind::kString && e->value.text == "all") {
      *all = true;
      return {};
    }
    return list(key, Kind::kString);
  }

  // The keys starting with `prefix` ("param." or "problem_param.").
  std::vector<const MatrixEntry*> params(const std::string& prefix) const {
    std::vector<const MatrixEntry*> out;
    for (const auto& [key, e] : values_)
      if (key.rfind(prefix, 0) == 0) out.push_back(e);
    // file order: defaults first, then the sweep's own
    std::sort(out.begin(), out.end(), [](const MatrixEntry* a, const MatrixEntry* b) {
      return std::make_pair(a->where.line, a->where.column) < std::make_pair(b->where.line, b->where.column);
    });
    return out;
  }

 private:
  const MatrixSection& sweep_;
  std::map<std::string, const MatrixEntry*> values_;
};

void check_keys(const MatrixSection& sec) {
  for (const auto& e : sec.entries) {
    if (e.key.rfind("param.", 0) == 0 || e.key.rfind("problem_param.", 0) == 0) {
      const size_t dots = std::count(e.key.begin(), e.key.end(), '.');
      const std::string head = e.key.substr(0, e.key.find('.'));
      const std::string owner = head == "param" ? "METHOD" : "PROBLEM";
      if (dots > 2)
        throw MatrixError(e.where, "'" + e.key + "': write " + head + ".NAME or " + head + "." + owner + ".NAME");
      continue;
    }
    if (sec.kind != "defaults" && e.key == "plugins")
      throw MatrixError(e.where, "'plugins' belongs in [defaults]: a file's plugins load before any sweep");
    if (sec.kind == "defaults" && e.key == "name")
      throw MatrixError(e.where, "'name' belongs in a [[sweep]], not in [defaults]");
    const auto& known = known_keys();
    if (std::find(known.begin(), known.end(), e.key) == known.end())
      throw MatrixError(e.where, "unknown key '" + e.key + "'" + suggestion(e.key, known) +
                                     "; known: " + join(known, ", ") +
                                     ", param.NAME, param.METHOD.NAME, problem_param.NAME, problem_param.PROBLEM.NAME");
  }
}

struct TEnd {
  std::string mode;  // "", "ref", "default"
  double value = 0;
  SourceLocation where;
};

struct ParamChoice {
  std::string owner;  // the method (param.) or problem (problem_param.) it is for; empty: any declaring `name`
  std::string name;
  std::vector<const MatrixValue*> values;
  SourceLocation where;
  bool used = false;
};

// "a=1;b=2", in the given order.
std::string join_params(const std::vector<std::pair<std::string, std::string>>& params) {
  std::string out;
  for (const auto& [k, v] : params) out += (out.empty() ? "" : ";") + k + "=" + v;
  return out;
}

double estimate_cost(const RunConfig& c, const IntegratorInfo& integ, int repeats) {
  double evals;
  if (integ.fixed_step) {
    evals = c.t_end / c.step.step * (integ.name == "rk4" ? 4 : 2);
  } else {
    const double tol = std::min(c.step.rtol, c.step.atol);
    evals = c.t_end * 50 * std::pow(tol, -1.0 / std::max(integ.order, 1)) * 10;
  }
  return evals * repeats;
}

// `timeout_text`: "0" for the default timeout (the text every id had
// before the default existed, so ids stay), "none" for an explicit 0, else
// the number.
std::string canonical_text(const RunConfig& c, int repeats, const std::string& timeout_text, double repeat_if_under) {
  const std::string params = join_params(c.params);
  std::string times;
  for (double t : c.times) {
    if (!times.empty()) times += ',';
    times += format_exact(t);
  }
  std::ostringstream s;
  s << "problem=" << c.problem << "\nmethod=" << c.method << "\nformulation=" << c.formulation
    << "\nintegrator=" << c.integrator << "\nstep=" << format_exact(c.step.step)
    << "\nrtol=" << format_exact(c.step.rtol) << "\natol=" << format_exact(c.step.atol) << "\nparams=" << params
    << "\nt_end=" << format_exact(c.t_end) << "\ntimes=" << times << "\nsample_every=" << format_exact(c.sample_every)
    << "\nref_time=" << format_exact(c.ref_time) << "\nblowup=" << format_exact(c.blowup)
    << "\nobserve_every=" << c.observe_every << "\nseries=" << (c.write_series ? 1 : 0) << "\nrepeats=" << repeats
    << "\ntimeout=" << timeout_text;
  if (repeat_if_under > 0) s << "\nrepeat_if_under=" << format_exact(repeat_if_under);
  // Only when set, so that the ids of unperturbed cases stay what they were.
  if (c.perturb > 0) s << "\nperturb=" << format_exact(c.perturb);
  if (c.max_steps != kDefaultMaxSteps) s << "\nmax_steps=" << format_exact(c.max_steps);
  if (!c.problem_params.empty()) s << "\nproblem_params=" << join_params(c.problem_params);
  s << "\n";
  return s.str();
}

}  // namespace

std::string CaseEntry::problem_label() const {
  return problem_params.empty() ? problem : problem + "(" + problem_params + ")";
}

bool CaseEntry::tuned() const {
  return curve.size() >= kTunedSuffix.size() &&
         std::string_view(curve).substr(curve.size() - kTunedSuffix.size()) == kTunedSuffix;
}

std::string CaseEntry::label() const {
  std::string s = problem_label() + " " + method + (formulation.empty() ? "" : "[" + formulation + "]") + " " +
                  integrator +
                  " " + setting + " t_end=" + format_short(t_end);
  if (!params.empty()) s += " " + params;
  if (repeats > 1) s += " x" + std::to_string(repeats);
  return s;
}

// Limits on one matrix (the default one has under 1000 cases).
constexpr size_t kMaxCases = 100000;

namespace {

// One [[sweep]] with every choice of its product read and checked; the
// counters are filled while the product is built.
struct SweepPlan {
  const MatrixSection* sec = nullptr;
  std::string name;
  bool optional = false;
  bool every_problem = false, every_method = false;
  std::vector<const Problem*> problems;
  std::vector<const MethodInfo*> methods;
  std::vector<const IntegratorInfo*> integrators;
  std::vector<const MatrixValue*> steps, tols, rtols, atols;
  std::vector<TEnd> t_ends;
  std::vector<const MatrixValue*> formulations, times;
  const MatrixValue* ref_time_value = nullptr;  // for messages
  double ref_time = -1, sample_every = 0, blowup = 1e3, timeout = kDefaultCaseTimeout, repeat_if_under = 0;
  std::string timeout_text = "0";  // canonical_text's
  double max_steps = kDefaultMaxSteps;
  const MatrixValue* max_steps_value = nullptr;  // for messages
  int observe_every = 1, repeats = 1;
  bool series = true, keep_series = false, work_precision = true, overlay = false;
  std::vector<double> perturbs;
  int tune = 0;  // gains per tuned method (0: no tuning)
  std::vector<ParamChoice> params, problem_params;
  // The given problem parameters of the problem variant being expanded.
  std::vector<std::pair<std::string, std::string>> given_problem_params;
  size_t not_applicable = 0, wrong_integrator = 0, wrong_integrator_own = 0;
};

// Builds the cases of every sweep, in order, keeping identical ones once.
class Expander {
 public:
  explicit Expander(const MatrixCatalog& catalog) : catalog_(catalog) {}

  // Stage 0: the whole file (key checks first, then each sweep).
  Expansion run(const MatrixFile& file) {
    const MatrixSection* defaults = nullptr;
    for (const auto& sec : file.sections) {
      check_keys(sec);
      if (sec.kind == "defaults") defaults = &sec;
    }
    int sweep_number = 0;
    for (const auto& sec : file.sections)
      if (sec.kind == "sweep") expand_sweep(Settings(defaults, sec), sec, ++sweep_number);
    if (duplicates_)
      out_.notes.push_back(std::to_string(duplicates_) + " duplicate cases dropped (same configuration)");
    if (sweep_number == 0) throw MatrixError({file.name, 1, 1}, "no [[sweep]] table: nothing to run");
    return std::move(out_);
  }

 private:
  // One sweep: read its choices, build its product, check it made cases.
  void expand_sweep(const Settings& set, const MatrixSection& sec, int number) {
    SweepPlan p;
    p.sec = &sec;
    read_name(set, number, p);
    const size_t notes_before = out_.notes.size(), cases_before = out_.cases.size();
    const size_t duplicates_before = duplicates_;
    if (set.find("external") || set.find("external_name")) {
      expand_external(set, p);
      finish_sweep(p, notes_before, cases_before, duplicates_before);
      return;
    }
    resolve_problems(set, p);
    resolve_methods(set, p);
    resolve_integrators(set, p);
    read_step_settings(set, p);
    read_t_ends(set, p);
    read_run_settings(set, p);
    p.params = read_param_choices(set, p, "param.");
    p.problem_params = read_param_choices(set, p, "problem_param.");
    check_formulations(p);
    for (const Problem* registered : p.problems)
      for_each_variant(p, *registered, [&](const Problem& problem) {
        for (const MethodInfo* method : p.methods) expand_pair(p, problem, *method);
      });
    finish_sweep(p, notes_before, cases_before, duplicates_before);
  }

  void note(const SweepPlan& p, const std::string& text) { out_.notes.push_back("sweep '" + p.name + "': " + text); }

  // Stage 1: `optional` and the sweep's name (unique, usable in a CSV cell).
  void read_name(const Settings& set, int number, SweepPlan& p) {
    p.optional = set.boolean("optional", false);
    p.name = "sweep" + std::to_string(number);
    if (const MatrixValue* v = set.scalar("name", Kind::kString)) {
      if (v->text.empty() || v->text.find_first_of(",\"\n") != std::string::npos)
        throw MatrixError(v->where, "name: must be non-empty, without commas or quotes");
      p.name = v->text;
      if (!seen_names_.insert(p.name).second)
        throw MatrixError(v->where, "name: '" + p.name + "' used by another sweep");
    }
  }

  // Stage 2: `problems`, "all" or names of the catalog.
  void resolve_problems(const Settings& set, SweepPlan& p) {
    const auto names = set.names("problems", &p.every_problem);
    if (p.every_problem) {
      p.problems = catalog_.problems;
      return;
    }
    if (names.empty()) throw MatrixError(p.sec->where, "sweep '" + p.name + "' has no 'problems'");
    for (const auto* v : names) {
      auto it = std::find_if(catalog_.problems.begin(), catalog_.problems.end(),
                             [&](const Problem* pr) { return pr->info().name == v->text; });
      if (it != catalog_.problems.end()) {
        p.problems.push_back(*it);
        continue;
      }
      std::vector<std::string> known;
      for (const auto* pr : catalog_.problems) known.push_back(pr->info().name);
      if (p.optional) {
        note(p, "problem '" + v->text + "' is not in this build (optional sweep): skipped");
        continue;
      }
      throw MatrixError(v->where, "unknown problem '" + v->text + "'" + suggestion(v->text, known) +
                                      " (known: " + join(known, ", ") + "; or \"all\")");
    }
  }

  // Stage 3: `methods`, "all" or names of the catalog.
  void resolve_methods(const Settings& set, SweepPlan& p) {
    const auto names = set.names("methods", &p.every_method);
    if (p.every_method) {
      for (const auto& m : catalog_.methods) p.methods.push_back(&m);
      return;
    }
    if (names.empty()) throw MatrixError(p.sec->where, "sweep '" + p.name + "' has no 'methods'");
    for (const auto* v : names) {
      auto it = std::find_if(catalog_.methods.begin(), catalog_.methods.end(),
                             [&](const MethodInfo& m) { return m.name == v->text; });
      if (it != catalog_.methods.end()) {
        p.methods.push_back(&*it);
        continue;
      }
      std::vector<std::string> known;
      for (const auto& m : catalog_.methods) known.push_back(m.name);
      if (p.optional) {
        note(p, "method '" + v->text + "' is not in this build (optional sweep): skipped");
        continue;
      }
      throw MatrixError(v->where, "unknown method '" + v->text + "'" + suggestion(v->text, known) +
                                      " (known: " + join(known, ", ") + "; or \"all\")");
    }
  }

  // Stage 4: `integrators`, "all" or names of this build.
  void resolve_integrators(const Settings& set, SweepPlan& p) {
    bool every = false;
    const auto names = set.names("integrators", &every);
    if (every) {
      for (const auto& i : all_integrators()) p.integrators.push_back(&i);
      return;
    }
    if (names.empty()) throw MatrixError(p.sec->where, "sweep '" + p.name + "' has no 'integrators'");
    for (const auto* v : names) {
      auto it = std::find_if(all_integrators().begin(), all_integrators().end(),
                             [&](const IntegratorInfo& i) { return i.name == v->text; });
      if (it == all_integrators().end() && p.optional) {
        note(p, "integrator '" + v->text + "' is not in this build (optional sweep): skipped");
        continue;
      }
      if (it == all_integrators().end()) {
        std::vector<std::string> known;
        for (const auto& i : all_integrators()) known.push_back(i.name);
        throw MatrixError(v->where, "unknown integrator '" + v->text + "'" + suggestion(v->text, known) +
                                        " (known: " + join(known, ", ") + ")");
      }
      p.integrators.push_back(&*it);
    }
  }

  // Stage 5: `step` / `tol` / `rtol` + `atol`, each what its integrators need.
  static void read_step_settings(const Settings& set, SweepPlan& p) {
    p.steps = set.list("step", Kind::kNumber);
    p.tols = set.list("tol", Kind::kNumber);
    p.rtols = set.list("rtol", Kind::kNumber);
    p.atols = set.list("atol", Kind::kNumber);
    for (const auto* list : {&p.steps, &p.tols, &p.rtols, &p.atols})
      for (const auto* v : *list)
        if (!(v->number > 0)) throw MatrixError(v->where, "step sizes and tolerances must be > 0");
    if (!p.tols.empty() && (!p.rtols.empty() || !p.atols.empty()))
      throw MatrixError(set.find("tol")->where, "give either 'tol' (rtol = atol) or 'rtol' and 'atol', not both");
    if (p.tols.empty() && (p.rtols.empty() != p.atols.empty()))
      throw MatrixError((p.rtols.empty() ? set.find("atol") : set.find("rtol"))->where,
                        "'rtol' and 'atol' go together (or use 'tol' for both)");
    const bool have_tol = !p.tols.empty() || !p.rtols.empty();
    bool any_fixed = false, any_adaptive = false;
    for (const auto* i : p.integrators) {
      (i->fixed_step ? any_fixed : any_adaptive) = true;
      const MatrixEntry* ie = set.find("integrators");
      const SourceLocation& at = ie ? ie->where : p.sec->where;
      if (i->fixed_step && p.steps.empty())
        throw MatrixError(at, "integrator '" + i->name + "' is fixed-step: the sweep needs 'step'");
      if (!i->fixed_step && !have_tol)
        throw MatrixError(at, "integrator '" + i->name + "' is adaptive: the sweep needs 'tol' (or 'rtol' and 'atol')");
    }
    if (!p.steps.empty() && !any_fixed && !p.integrators.empty())
      throw MatrixError(set.find("step")->where, "'step' given but no integrator of the sweep is fixed-step");
    if (have_tol && !any_adaptive && !p.integrators.empty())
      throw MatrixError((p.tols.empty() ? set.find("rtol") : set.find("tol"))->where,
                        "tolerances given but no integrator of the sweep is adaptive");
  }

  // Stage 6: `t_end`, numbers, "ref" or "default" (one value or an array).
  static void read_t_ends(const Settings& set, SweepPlan& p) {
    const MatrixEntry* e = set.find("t_end");
    if (!e) {
      p.t_ends.push_back({"default", 0, p.sec->where});
      return;
    }
    std::vector<const MatrixValue*> vals;
    if (e->value.kind == Kind::kArray)
      for (const auto& item : e->value.items) vals.push_back(&item);
    else
      vals.push_back(&e->value);
    for (const auto* v : vals) {
      if (v->kind == Kind::kString && (v->text == "ref" || v->text == "default")) {
        p.t_ends.push_back({v->text, 0, v->where});
      } else if (v->kind == Kind::kNumber && v->number > 0) {
        p.t_ends.push_back({"", v->number, v->where});
      } else {
        throw MatrixError(v->where, "t_end: expected a number > 0, \"ref\" (the problem's reference time) or "
                                    "\"default\" (the problem's default horizon)");
      }
    }
  }

  // Stage 7: observation, repeats, timeout, flags and `perturb`.
  static void read_run_settings(const Settings& set, SweepPlan& p) {
    p.formulations = set.list("formulations", Kind::kString);
    p.times = set.list("times", Kind::kNumber);
    p.ref_time = set.number("ref_time", -1);
    if (const MatrixEntry* e = set.find("ref_time")) p.ref_time_value = &e->value;
    p.sample_every = set.number("sample_every", 0);
    p.blowup = set.number("blowup", 1e3);
    const double observe_every = set.number("observe_every", 1);
    const double repeats = set.number("repeats", 1);
    p.timeout = set.number("timeout", kDefaultCaseTimeout);
    if (set.find("timeout")) p.timeout_text = p.timeout == 0 ? "none" : format_exact(p.timeout);
    p.max_steps = set.number("max_steps", kDefaultMaxSteps);
    if (const MatrixEntry* e = set.find("max_steps")) p.max_steps_value = &e->value;
    p.repeat_if_under = set.number("repeat_if_under", 0);
    auto check = [&](const char* key, bool ok, const std::string& what) {
      if (set.find(key) && !ok) throw MatrixError(set.find(key)->value.where, std::string(key) + ": " + what);
    };
    check("ref_time", p.ref_time >= 0, "must be >= 0 (0: no reference error)");
    check("sample_every", p.sample_every >= 0, "must be >= 0 (0: t_end / 1000)");
    check("blowup", p.blowup > 0, "must be > 0");
    check("observe_every", observe_every >= 1 && observe_every <= 1e9 && observe_every == std::floor(observe_every),
          "must be an integer in [1, 1e9]");
    for (const auto* v : p.times)
      if (!(v->number > 0)) throw MatrixError(v->where, "times: " + v->text + " must be > 0");
    check("repeats", repeats >= 1 && repeats <= 1000 && repeats == std::floor(repeats),
          "must be an integer in [1, 1000]");
    check("timeout", p.timeout >= 0, "must be >= 0 seconds (0: none)");
    check("max_steps", p.max_steps >= 1 && p.max_steps <= 1e15, "must be a number in [1, 1e15]");
    check("repeat_if_under", p.repeat_if_under >= 0, "must be >= 0 seconds (0: always repeat)");
    p.observe_every = int(observe_every);
    p.repeats = int(repeats);
    p.series = set.boolean("series", true);
    p.keep_series = set.boolean("keep_series", false);
    for (const auto* v : set.list("perturb", Kind::kNumber)) {
      if (!std::isfinite(v->number) || v->number < 0)
        throw MatrixError(v->where, "perturb: must be a number >= 0 (0: consistent start)");
      p.perturbs.push_back(v->number);
    }
    if (p.perturbs.empty()) p.perturbs.push_back(0);
    p.work_precision = set.boolean("work_precision", true);
    p.overlay = set.boolean("overlay", false);
    const double tune = set.number("tune", 0);
    check("tune", tune == 0 || (tune >= 2 && tune <= 25 && tune == std::floor(tune)),
          "must be an integer in [2, 25] (gains per method) or 0 (no tuning)");
    p.tune = int(tune);
  }

  // Stage 8: the `param.NAME` and `param.METHOD.NAME` keys (prefix "param."),
  // or `problem_param.NAME` and `problem_param.PROBLEM.NAME`, in file order.
  std::vector<ParamChoice> read_param_choices(const Settings& set, const SweepPlan& p,
                                              const std::string& prefix) const {
    std::vector<ParamChoice> out;
    for (const MatrixEntry* e : set.params(prefix)) {
      ParamChoice pc;
      const std::string rest = e->key.substr(prefix.size());
      const size_t dot = rest.find('.');
      pc.name = rest.substr(dot == std::string::npos ? 0 : dot + 1);
      if (dot != std::string::npos) {
        pc.owner = rest.substr(0, dot);
        if (!known_owner(prefix, pc.owner) && !p.optional)
          throw MatrixError(e->where, "'" + e->key + "': unknown " + (prefix == "param." ? "method" : "problem") +
                                          " '" + pc.owner + "'");
      }
      pc.where = e->where;
      if (e->value.kind == Kind::kArray) {
        if (e->value.items.empty()) throw MatrixError(e->value.where, e->key + ": empty array");
        for (const auto& item : e->value.items) pc.values.push_back(&item);
      } else {
        pc.values.push_back(&e->value);
      }
      for (const auto* v : pc.values)
        if (v->kind != Kind::kNumber) throw MatrixError(v->where, e->key + ": expected a number");
      out.push_back(std::move(pc));
    }
    return out;
  }

  bool known_owner(const std::string& prefix, const std::string& owner) const {
    if (prefix == "param.")
      return std::any_of(catalog_.methods.begin(), catalog_.methods.end(),
                         [&](const MethodInfo& m) { return m.name == owner; });
    return std::any_of(catalog_.problems.begin(), catalog_.problems.end(),
                       [&](const Problem* pr) { return pr->info().name == owner; });
  }

  // Stage 8a: each combination of the sweep's problem_param.* values that
  // apply to `registered` (the problem itself when none do), checked
  // against the problem's ranges.
  template <class Body>
  void for_each_variant(SweepPlan& p, const Problem& registered, const Body& body) {
    const std::string& name = registered.info().name;
    const std::vector<ParamChoice*> applying =
        applying_choices(p.problem_params, registered.problem_params(), name, "problem '" + name + "'",
                         "problem_param.", "problem '" + name + "'");
    for_each_combination(applying, [&](const std::vector<std::pair<std::string, std::string>>& given) {
      p.given_problem_params = given;
      std::unique_ptr<Problem> variant;
      try {
        variant = problem_variant(registered, given);
      } catch (const UsageError& e) {
        throw MatrixError(applying.front()->where, e.what());
      }
      body(variant ? *variant : registered);
    });
    p.given_problem_params.clear();
  }

  // Stage 9: every formulation named belongs to one of the sweep's problems.
  static void check_formulations(const SweepPlan& p) {
    for (const auto* f : p.formulations) {
      const bool known = std::any_of(p.problems.begin(), p.problems.end(), [&](const Problem* pr) {
        const auto& fs = pr->info().formulations;
        return std::any_of(fs.begin(), fs.end(), [&](const FormulationInfo& fi) { return fi.name == f->text; });
      });
      if (known || p.problems.empty()) continue;
      std::vector<std::string> names;
      for (const Problem* pr : p.problems)
        for (const auto& fi : pr->info().formulations)
          if (std::find(names.begin(), names.end(), fi.name) == names.end()) names.push_back(fi.name);
      throw MatrixError(f->where, "unknown formulation '" + f->text + "'" + suggestion(f->text, names) +
                                      " for the sweep's problems (known: " + join(names, ", ") + ")");
    }
  }

  // Stage 10: one problem x method pair: a note if it does not apply, else its formulations x integrators.
  void expand_pair(SweepPlan& p, const Problem& problem, const MethodInfo& method) {
    const ProblemInfo& info = problem.info();
    const std::string why = problem.why_not(method.name);
    if (!why.empty()) {
      if (!p.every_method && !p.every_problem) note(p, method.name + " does not apply to " + info.name + ": " + why);
      ++p.not_applicable;
      return;
    }
    // Parameters this method declares on this problem.
    std::vector<ParamSpec> specs;
    try {
      specs = problem.method_params(method.name, "");
    } catch (const UsageError& e) {
      note(p, method.name + " on " + info.name + ": " + e.what());
      return;
    }
    // A DAE formulation F(t, y, y') = 0 needs a DAE integrator and an
    // ODE one an ODE integrator (the method declares which it is,
    // MethodInfo::kind; likewise a method that steps itself and the "own"
    // integrator): impossible pairs are not cases.
    const std::vector<ParamChoice*> applying = applying_params(p, info, method, specs);
    const Tuning tuning = tuning_of(p, info, method, specs, applying);
    std::vector<std::string> forms;
    for (const auto* f : p.formulations) forms.push_back(f->text);
    if (forms.empty()) forms.push_back("");
    check_budget(p, forms.size() * (1 + tuning.gains.size()), applying);
    for (const std::string& form : forms) {
      if (!form.empty()) {
        try {
          problem.method_params(method.name, form);
        } catch (const UsageError&) {
          note(p, method.name + " on " + info.name + " has no formulation '" + form + "': skipped");
          continue;
        }
      }
      for (const IntegratorInfo* integ : p.integrators) {
        if (method.kind != integ->kind) {
          const bool own = method.kind == MethodKind::kSelfStepping || integ->kind == MethodKind::kSelfStepping;
          ++(own ? p.wrong_integrator_own : p.wrong_integrator);
          continue;
        }
        for (const TEnd& te : p.t_ends) expand_run(p, info, method, form, *integ, te, applying, tuning);
      }
    }
  }

  // Key `tune = N`: the method's declared gain at N values (harness/tune:
  // tune_gains, 3 decades around its default), its tied parameters alike,
  // beside its default-gain cases; none for a method without a gain.
  struct Tuning {
    const ParamSpec* gain = nullptr;
    std::vector<double> gains;
  };
  Tuning tuning_of(const SweepPlan& p, const ProblemInfo& info, const MethodInfo& method,
                   const std::vector<ParamSpec>& specs, const std::vector<ParamChoice*>& applying) {
    Tuning t;
    if (p.tune == 0) return t;
    t.gain = find_gain(specs);
    if (!t.gain) {
      if (!p.every_method) note(p, "tune: " + method.name + " declares no gain: its default cases only");
      return t;
    }
    for (const ParamChoice* pc : applying)
      if (pc->name == t.gain->name ||
          std::find(t.gain->swept_with.begin(), t.gain->swept_with.end(), pc->name) != t.gain->swept_with.end())
        throw MatrixError(pc->where, "param." + pc->name + ": tune sweeps " + method.name + "'s gain '" +
                                         t.gain->name + "' itself (on problem '" + info.name +
                                         "'): give one or the other");
    if (!(t.gain->default_value > 0)) {
      // e.g. Braun-Goldfarb's dt = 0, "the integrator's step": no scale to spread gains around.
      if (!p.every_method)
        note(p, "tune: " + method.name + "'s gain '" + t.gain->name + "' defaults to " +
                    format_short(t.gain->default_value) + ": no scale to tune around (param." + method.name + "." +
                    t.gain->name + " sweeps it): its default cases only");
      t.gain = nullptr;
      return t;
    }
    t.gains = tune_gains(*t.gain, p.tune);
    return t;
  }

  // Stage 10a: the sweep's param.* keys that apply to this method, their values within its bounds.
  static std::vector<ParamChoice*> applying_params(SweepPlan& p, const ProblemInfo& info, const MethodInfo& method,
                                                   const std::vector<ParamSpec>& specs) {
    return applying_choices(p.params, specs, method.name, "method '" + method.name + "'", "param.",
                            "method '" + method.name + "' on problem '" + info.name + "'");
  }

  // The choices that apply to `owner` (named by it, or unqualified and
  // declared in `specs`), their values checked against the specs' ranges.
  static std::vector<ParamChoice*> applying_choices(std::vector<ParamChoice>& choices,
                                                    const std::vector<ParamSpec>& specs, const std::string& owner,
                                                    const std::string& owner_text, const std::string& prefix,
                                                    const std::string& context) {
    std::vector<ParamChoice*> applying;
    for (auto& pc : choices) {
      if (!pc.owner.empty() && pc.owner != owner) continue;
      const auto spec = std::find_if(specs.begin(), specs.end(), [&](const ParamSpec& s) { return s.name == pc.name; });
      if (spec == specs.end()) {
        if (!pc.owner.empty()) {
          std::vector<std::string> known;
          for (const auto& s : specs) known.push_back(s.name + " (" + bound_text(s) + ")");
          throw MatrixError(pc.where, context + " has no parameter '" + pc.name + "' (known: " +
                                          (known.empty() ? "none" : join(known, ", ")) + ")");
        }
        continue;
      }
      for (const auto* v : pc.values) {
        const std::string problem = param_value_problem(*spec, v->number);
        if (!problem.empty())
          throw MatrixError(v->where, prefix + pc.name + " = " + v->text + ": " + problem + " for " + owner_text);
      }
      pc.used = true;
      applying.push_back(&pc);
    }
    return applying;
  }

  // Calls body(values) for every combination of the choices' values (once, with none, for no choices).
  template <class Body>
  static void for_each_combination(const std::vector<ParamChoice*>& choices, const Body& body) {
    std::vector<size_t> pick(choices.size(), 0);
    while (true) {
      std::vector<std::pair<std::string, std::string>> values;
      for (size_t i = 0; i < choices.size(); ++i)
        values.emplace_back(choices[i]->name, format_short(choices[i]->values[pick[i]]->number));
      body(values);
      size_t i = 0;
      while (i < pick.size() && ++pick[i] == choices[i]->values.size()) pick[i++] = 0;
      if (i == pick.size()) break;
    }
  }

  // Stage 10b: the case budget (a bound of what this pair adds), checked before any case is built.
  void check_budget(const SweepPlan& p, size_t forms, const std::vector<ParamChoice*>& applying) {
    double planned_here =
        double(forms) * double(p.integrators.size()) * double(p.t_ends.size()) *
        double(std::max({p.steps.size(), p.tols.size(), p.rtols.size() * p.atols.size(), size_t(1)}));
    planned_here *= double(p.perturbs.size());
    for (const ParamChoice* pc : applying) planned_here *= double(pc->values.size());
    planned_ += planned_here;
    if (planned_ > double(kMaxCases))
      throw MatrixError(p.sec->where, "the matrix expands to more than " + std::to_string(kMaxCases) +
                                          " cases: split it into several files");
  }

  // Stage 11: one t_end: output times checked, then parameter combinations x step settings x perturb.
  void expand_run(const SweepPlan& p, const ProblemInfo& info, const MethodInfo& method, const std::string& form,
                  const IntegratorInfo& integ, const TEnd& te, const std::vector<ParamChoice*>& applying,
                  const Tuning& tuning) {
    double t_end = te.value;
    if (te.mode == "ref") t_end = info.reference_time > 0 ? info.reference_time : info.default_t_end;
    if (te.mode == "default") t_end = info.default_t_end;
    if (p.ref_time > t_end)
      throw MatrixError(p.ref_time_value->where, "ref_time: " + p.ref_time_value->text + " is beyond t_end " +
                                                     format_short(t_end) + " (problem '" + info.name + "')");
    for (const auto* v : p.times)
      if (v->number > t_end)
        throw MatrixError(v->where, "times: " + v->text + " is beyond t_end " + format_short(t_end) +
                                        " (problem '" + info.name + "')");
    std::vector<StepSettings> settings;
    if (integ.fixed_step) {
      for (const auto* v : p.steps) {
        if (v->number > t_end) {
          note(p, info.name + ": step " + v->text + " larger than t_end " + format_short(t_end) + ": skipped");
          continue;
        }
        if (!(t_end / v->number <= p.max_steps))
          throw MatrixError(v->where, "step: " + v->text + " needs t_end / step = " + format_3g(t_end / v->number) +
                                          " steps (problem '" + info.name + "'), more than max_steps = " +
                                          format_short(p.max_steps) + " (the key max_steps raises it)");
        settings.push_back({v->number, 0, 0});
      }
    } else if (!p.tols.empty()) {
      for (const auto* v : p.tols) settings.push_back({0, v->number, v->number});
    } else {
      for (const auto* r : p.rtols)
        for (const auto* a : p.atols) settings.push_back({0, r->number, a->number});
    }
    for_each_combination(applying, [&](const std::vector<std::pair<std::string, std::string>>& params) {
      for (const StepSettings& st : settings)
        for (const double perturb : p.perturbs) add_case(p, info, method, form, integ, t_end, params, st, perturb);
      // The tuned cases: the gain (and its tied parameters) at each value;
      // one curve "... tuned" per method, formulation, integrator and other
      // parameters, whose envelope the report draws.
      for (const double g : tuning.gains) {
        RunConfig gained;
        gained.params = params;
        apply_gain(gained, *tuning.gain, g);
        for (const StepSettings& st : settings)
          for (const double perturb : p.perturbs)
            add_case(p, info, method, form, integ, t_end, gained.params, st, perturb, params.size());
      }
    });
  }

  // The case's id and entry from its configuration; false (counted) if an
  // identical case is already in the expansion.
  bool claim_entry(const SweepPlan& p, MatrixCase& c) {
    const RunConfig& cfg = c.config;
    CaseEntry& e = c.entry;
    e.id = hash_hex(c.config_text);
    if (!seen_ids_.insert(e.id).second) {
      ++duplicates_;
      return false;
    }
    e.index = out_.cases.size();
    e.sweep = p.name;
    e.problem = cfg.problem;
    e.problem_params = join_params(cfg.problem_params);
    e.method = cfg.method;
    e.formulation = cfg.formulation;
    e.integrator = cfg.integrator;
    e.params = join_params(cfg.params);
    e.t_end = cfg.t_end;
    e.repeats = p.repeats;
    e.work_precision = p.work_precision;
    e.overlay = p.overlay;
    return true;
  }

  // Stage 12: one case, unless an identical one is already in the expansion.
  void add_case(const SweepPlan& p, const ProblemInfo& info, const MethodInfo& method, const std::string& form,
                const IntegratorInfo& integ, double t_end, const std::vector<std::pair<std::string, std::string>>& params,
                const StepSettings& st, double perturb, size_t tuned_from = std::string::npos) {
    MatrixCase c;
    RunConfig& cfg = c.config;
    cfg.problem = info.name;
    cfg.problem_params = p.given_problem_params;
    cfg.method = method.name;
    cfg.formulation = form;
    cfg.integrator = integ.name;
    cfg.params = params;
    cfg.step = st;
    cfg.t_end = t_end;
    for (const auto* v : p.times) cfg.times.push_back(v->number);
    cfg.sample_every = p.sample_every;
    cfg.ref_time = p.ref_time;
    cfg.blowup = p.blowup;
    cfg.observe_every = p.observe_every;
    cfg.write_series = p.series;
    cfg.perturb = perturb;
    cfg.max_steps = p.max_steps;
    c.timeout = p.timeout;
    c.repeat_if_under = p.repeat_if_under;
    c.keep_series = p.keep_series;
    c.config_text = canonical_text(cfg, p.repeats, p.timeout_text, p.repeat_if_under);
    if (!claim_entry(p, c)) return;
    CaseEntry& e = c.entry;
    if (integ.fixed_step)
      e.setting = "step=" + format_short(st.step);
    else if (st.rtol == st.atol)
      e.setting = "tol=" + format_short(st.rtol);
    else
      e.setting = "rtol=" + format_short(st.rtol) + ";atol=" + format_short(st.atol);
    if (perturb > 0) e.setting += ";perturb=" + format_short(perturb);
    // A tuned case (params from index tuned_from on are the tuned gain's):
    // its curve is named without them, and ends in " tuned".
    const bool tuned = tuned_from != std::string::npos;
    const std::string curve_params =
        tuned ? join_params(std::vector<std::pair<std::string, std::string>>(
                    params.begin(), params.begin() + std::ptrdiff_t(tuned_from)))
              : e.params;
    e.curve = e.method + (form.empty() ? "" : "[" + form + "]") + "/" + e.integrator +
              (curve_params.empty() ? "" : " " + curve_params) +
              (e.problem_params.empty() ? "" : " (" + e.problem_params + ")") + (tuned ? std::string(kTunedSuffix) : std::string());
    c.cost_estimate = estimate_cost(cfg, integ, p.repeats);
    out_.cases.push_back(std::move(c));
  }

  // An external sweep (keys `external`, `external_name`): an outside
  // program is the method and the integrator. Its command template is
  // completed per case ({problem}, {t_end}, {step} or {tol}, and {out}, the
  // trajectory file it must write, filled in by the worker) and the case
  // scores what it wrote (harness/score.hpp).
  void expand_external(const Settings& set, SweepPlan& p) {
    const MatrixValue* cmd = set.scalar("external", Kind::kString);
    const MatrixValue* name = set.scalar("external_name", Kind::kString);
    const MatrixEntry* first = set.find("external") ? set.find("external") : set.find("external_name");
    if (!cmd) throw MatrixError(first->where, "external_name: given without 'external' (the command to run)");
    if (!name) throw MatrixError(first->where, "external: needs 'external_name' (the method column of its cases)");
    for (const char* key : {"methods", "integrators", "formulations", "perturb", "times", "observe_every", "tune"})
      if (const MatrixEntry* e = set.find(key))
        throw MatrixError(e->where, std::string(key) + ": not for an external sweep (its command is the method "
                                                        "and the integrator)");
    if (!set.params("param.").empty())
      throw MatrixError(set.params("param.").front()->where, "param.*: not for an external sweep (pass settings in "
                                                             "the command)");
    if (name->text.empty() || name->text.find_first_of(",\"\n ;[]/") != std::string::npos)
      throw MatrixError(name->where, "external_name: must be non-empty, without spaces, commas, quotes, ;, / or []");
    for (const auto& m : catalog_.methods)
      if (m.name == name->text)
        throw MatrixError(name->where, "external_name: '" + name->text + "' is a built-in method's name");
    read_step_settings(set, p);
    if (!p.rtols.empty())
      throw MatrixError(set.find("rtol")->where, "rtol/atol: an external sweep takes 'tol' (substituted as {tol})");
    check_template(cmd, p);
    resolve_problems(set, p);
    read_t_ends(set, p);
    read_run_settings(set, p);
    p.problem_params = read_param_choices(set, p, "problem_param.");
    std::vector<StepSettings> settings;
    for (const auto* v : p.steps) settings.push_back({v->number, 0, 0});
    for (const auto* v : p.tols) settings.push_back({0, v->number, v->number});
    if (settings.empty()) settings.push_back({});
    for (const Problem* registered : p.problems)
      for_each_variant(p, *registered, [&](const Problem& problem) {
        const ProblemInfo& info = problem.info();
        for (const TEnd& te : p.t_ends) {
          double t_end = te.value;
          if (te.mode == "ref") t_end = info.reference_time > 0 ? info.reference_time : info.default_t_end;
          if (te.mode == "default") t_end = info.default_t_end;
          for (const StepSettings& st : settings) add_external_case(p, info, name->text, cmd->text, t_end, st);
        }
      });
  }

  // The placeholders: known ones only, {out} required, {step}/{tol} only with their list.
  static void check_template(const MatrixValue* cmd, const SweepPlan& p) {
    const std::string& t = cmd->text;
    if (t.find("{out}") == std::string::npos)
      throw MatrixError(cmd->where, "external: the command must write its trajectory to {out}");
    for (size_t at = t.find('{'); at != std::string::npos; at = t.find('{', at + 1)) {
      const size_t close = t.find('}', at);
      const std::string key = t.substr(at, close == std::string::npos ? std::string::npos : close - at + 1);
      if (key != "{out}" && key != "{problem}" && key != "{t_end}" && key != "{step}" && key != "{tol}")
        throw MatrixError(cmd->where, "external: unknown placeholder '" + key +
                                          "' (known: {problem}, {t_end}, {step}, {tol}, {out})");
      if ((key == "{step}" && p.steps.empty()) || (key == "{tol}" && p.tols.empty()))
        throw MatrixError(cmd->where, "external: " + key + " used but the sweep has no '" +
                                          key.substr(1, key.size() - 2) + "' list");
    }
  }

  static std::string replaced(std::string text, const std::string& key, const std::string& value) {
    for (size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + value.size()))
      text.replace(at, key.size(), value);
    return text;
  }

  void add_external_case(const SweepPlan& p, const ProblemInfo& info, const std::string& name,
                         const std::string& command, double t_end, const StepSettings& st) {
    MatrixCase c;
    RunConfig& cfg = c.config;
    cfg.problem = info.name;
    cfg.problem_params = p.given_problem_params;
    cfg.method = name;
    cfg.integrator = "external";
    cfg.step = st;
    cfg.t_end = t_end;
    cfg.sample_every = p.sample_every;
    cfg.ref_time = p.ref_time;
    cfg.blowup = p.blowup;
    cfg.write_series = p.series;
    c.timeout = p.timeout;
    c.repeat_if_under = p.repeat_if_under;
    c.keep_series = p.keep_series;
    std::string problem_arg = info.name;
    for (const auto& [k, v] : cfg.problem_params) problem_arg += " --problem-param " + k + "=" + v;
    c.external = replaced(replaced(command, "{problem}", problem_arg), "{t_end}", format_short(t_end));
    if (st.step > 0) c.external = replaced(c.external, "{step}", format_short(st.step));
    if (st.rtol > 0) c.external = replaced(c.external, "{tol}", format_short(st.rtol));
    c.config_text = canonical_text(cfg, p.repeats, p.timeout_text, p.repeat_if_under) + "external=" + c.external + "\n";
    if (!claim_entry(p, c)) return;
    CaseEntry& e = c.entry;
    if (st.step > 0) e.setting = "step=" + format_short(st.step);
    if (st.rtol > 0) e.setting = "tol=" + format_short(st.rtol);
    e.curve = name + "/external" + (e.problem_params.empty() ? "" : " (" + e.problem_params + ")");
    c.cost_estimate = t_end * p.repeats;
    out_.cases.push_back(std::move(c));
  }

  // Stage 13: the sweep's notes; a sweep without a case is an error (unless optional), naming why.
  void finish_sweep(const SweepPlan& p, size_t notes_before, size_t cases_before, size_t duplicates_before) {
    for (const auto& pc : p.params)
      if (!pc.used && !p.optional)
        note(p, "param." + (pc.owner.empty() ? "" : pc.owner + ".") + pc.name + " (line " +
                    std::to_string(pc.where.line) + ") applies to no method of the sweep");
    for (const auto& pc : p.problem_params)
      if (!pc.used && !p.optional)
        note(p, "problem_param." + (pc.owner.empty() ? "" : pc.owner + ".") + pc.name + " (line " +
                    std::to_string(pc.where.line) + ") applies to no problem of the sweep");
    if (p.wrong_integrator)
      note(p, std::to_string(p.wrong_integrator) + " method x integrator combinations skipped: DAE methods (ida-*) "
              "need integrator 'ida', and 'ida' needs a DAE method");
    if (p.wrong_integrator_own) {
      std::vector<std::string> own;
      for (const MethodInfo& m : catalog_.methods)
        if (m.kind == MethodKind::kSelfStepping) own.push_back(m.name);
      note(p, std::to_string(p.wrong_integrator_own) + " method x integrator combinations skipped: methods that are "
              "their own scheme (" + join(own, ", ") + ") need integrator 'own', and 'own' needs one of them");
    }
    if (out_.cases.size() == cases_before && duplicates_ == duplicates_before && !p.optional) {
      std::string why;
      for (size_t i = notes_before; i < out_.notes.size(); ++i) why += "; " + out_.notes[i];
      throw MatrixError(p.sec->where, "sweep '" + p.name + "' expands to no case" +
                                          (why.empty() ? std::string() : why));
    }
    if (p.not_applicable && (p.every_method || p.every_problem))
      note(p, std::to_string(p.not_applicable) + " problem x method combinations do not apply (see `cstab list`)");
  }

  const MatrixCatalog& catalog_;
  Expansion out_;
  std::set<std::string> seen_ids_, seen_names_;
  size_t duplicates_ = 0;
  double planned_ = 0;  // upper bound of the cases so far
};

}  // namespace

Expansion expand_matrix(const MatrixFile& file, const MatrixCatalog& catalog) { return Expander(catalog).run(file); }

std::pair<int, int> parse_shard(const std::string& text) {
  const size_t slash = text.find('/');
  auto parse_int = [&](const std::string& s) {
    char* end = nullptr;
    const long v = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || *end != '\0') throw UsageError("--shard " + text + ": expected k/N, e.g. 2/4");
    return v;
  };
  if (slash == std::string::npos) throw UsageError("--shard " + text + ": expected k/N, e.g. 2/4");
  const long k = parse_int(text.substr(0, slash)), n = parse_int(text.substr(slash + 1));
  if (n < 1 || n > 100000 || k < 1 || k > n) throw UsageError("--shard " + text + ": need 1 <= k <= N");
  return {int(k), int(n)};
}

std::vector<MatrixCase> select_cases(const std::vector<MatrixCase>& cases, const std::string& filter,
                                     int shard_k, int shard_n) {
  std::vector<const MatrixCase*> kept;
  for (const auto& c : cases)
    if (filter.empty() || c.entry.label().find(filter) != std::string::npos || c.entry.id == filter ||
        c.entry.sweep == filter)
      kept.push_back(&c);
  if (shard_n > 1) {
    std::vector<const MatrixCase*> by_cost = kept;
    std::stable_sort(by_cost.begin(), by_cost.end(), [](const MatrixCase* a, const MatrixCase* b) {
      return a->cost_estimate > b->cost_estimate;
    });
    std::set<size_t> mine;
    for (size_t i = 0; i < by_cost.size(); ++i)
      if (int(i % shard_n) == shard_k - 1) mine.insert(by_cost[i]->entry.index);
    kept.erase(std::remove_if(kept.begin(), kept.end(), [&](const MatrixCase* c) { return !mine.count(c->entry.index); }),
               kept.end());
  }
  std::vector<MatrixCase> out;
  for (const auto* c : kept) out.push_back(*c);
  return out;
}

// ===========================================================================
// CSV reader

int CsvTable::column(const std::string& name) const {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return int(i);
  return -1;
}

const std::string& CsvTable::get(size_t row, const std::string& name) const {
  static const std::string empty;
  const int c = column(name);
  if (c < 0 || row >= rows.size() || size_t(c) >= rows[row].size()) return empty;
  return rows[row][c];
}

CsvTable read_csv(const std::string& path) { return parse_csv(read_text_file(path), path); }

namespace {

// RFC 4180 records with where each starts: one pass over the text, one
// character at a time (quoted fields may hold commas, newlines and "").
class CsvScanner {
 public:
  std::vector<std::vector<std::string>> records;
  std::vector<int> record_lines;                 // the line each record starts on
  std::vector<std::vector<int>> record_columns;  // the column each of its cells starts at

  void scan(const std::string& text, const std::string& path) {
    for (size_t i = 0; i < text.size(); ++i) {
      const char c = text[i];
      const int column = int(i - line_start_) + 1;
      if (at_field_start_ && !quoted_) {
        if (record_.empty()) record_line_ = line_;
        columns_.push_back(column);
        at_field_start_ = false;
      }
      if (c == '\n') {
        ++line_;
        line_start_ = i + 1;
      }
      if (quoted_)
        i += quoted_char(c, i + 1 < text.size() ? text[i + 1] : '\0');
      else
        plain_char(c, column);
    }
    if (quoted_)
      throw UsageError(path + ":" + std::to_string(quote_line_) + ":" + std::to_string(quote_column_) +
                       ": unterminated quoted field");
    if (field_started_ || !field_.empty() || !record_.empty()) end_record();
  }

 private:
  std::vector<std::string> record_;
  std::vector<int> columns_;
  std::string field_;
  bool quoted_ = false, field_started_ = false, at_field_start_ = true;
  int line_ = 1, record_line_ = 1, quote_line_ = 0, quote_column_ = 0;
  size_t line_start_ = 0;

  void end_record() {
    record_.push_back(std::move(field_));
    records.push_back(std::move(record_));
    record_columns.push_back(std::move(columns_));
    record_lines.push_back(record_line_);
    field_.clear();
    record_.clear();
    columns_.clear();
  }
  // Inside quotes; returns 1 when it consumed `next` too (a doubled quote).
  int quoted_char(char c, char next) {
    if (c != '"') {
      field_ += c;
      return 0;
    }
    if (next == '"') {
      field_ += '"';
      return 1;
    }
    quoted_ = false;
    return 0;
  }
  void plain_char(char c, int column) {
    if (c == '"' && field_.empty()) {
      quoted_ = true;
      quote_line_ = line_;
      quote_column_ = column;
      field_started_ = true;
    } else if (c == ',') {
      record_.push_back(std::move(field_));
      field_.clear();
      field_started_ = true;
      at_field_start_ = true;
    } else if (c == '\n') {
      if (field_started_ || !field_.empty() || !record_.empty())
        end_record();
      else
        columns_.clear();  // a blank line
      field_.clear();
      field_started_ = false;
      at_field_start_ = true;
    } else if (c != '\r') {
      field_ += c;
      field_started_ = true;
    }
  }
};

}  // namespace

CsvTable parse_csv(std::string text, const std::string& path) {
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);  // a UTF-8 byte order mark: allowed, skipped
  CsvScanner scan;
  scan.scan(text, path);
  CsvTable t;
  t.path = path;
  if (scan.records.empty()) return t;
  t.header = std::move(scan.records.front());
  t.rows.assign(std::make_move_iterator(scan.records.begin() + 1), std::make_move_iterator(scan.records.end()));
  t.row_lines.assign(scan.record_lines.begin() + 1, scan.record_lines.end());
  t.row_columns.assign(std::make_move_iterator(scan.record_columns.begin() + 1),
                       std::make_move_iterator(scan.record_columns.end()));
  return t;
}

std::string CsvTable::where(size_t row, const std::string& name) const {
  std::string s = path;
  if (row < row_lines.size()) {
    s += ":" + std::to_string(row_lines[row]);
    const int c = column(name);
    if (c >= 0 && row < row_columns.size() && size_t(c) < row_columns[row].size())
      s += ":" + std::to_string(row_columns[row][c]);
  }
  return s;
}

}  // namespace cstab
