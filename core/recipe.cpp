#include "core/recipe.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace segue {

template <> const char* type_name<double>() { return "a number"; }
template <> const char* type_name<float>() { return "a number"; }
template <> const char* type_name<int>() { return "an integer"; }
template <> const char* type_name<int64_t>() { return "an integer"; }
template <> const char* type_name<uint64_t>() { return "a non-negative integer"; }
template <> const char* type_name<bool>() { return "true or false"; }
template <> const char* type_name<std::string>() { return "a string"; }
template <> const char* type_name<std::vector<int>>() { return "a list of integers"; }
template <> const char* type_name<std::vector<double>>() { return "a list of numbers"; }
template <> const char* type_name<std::vector<std::string>>() { return "a list of strings"; }

namespace {

// A list index has at most four digits: a longer number is read as a key, since stoul
// would overflow on it and --set would pad a list up to it (both found by the fuzzer).
bool is_index(const std::string& part) {
  return !part.empty() && part.size() <= 4 && std::all_of(part.begin(), part.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::vector<std::string> split_key(const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  return parts;
}


void set_path(YAML::Node root, const std::vector<std::string>& parts, const YAML::Node& value) {
  // yaml-cpp nodes are handles: walk down by reassigning a handle copy.
  // Numeric parts index sequences ("transitions.0.from"), filled in order.
  std::vector<YAML::Node> chain{root};
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node parent = chain.back();
    bool next_is_index = is_index(parts[i + 1]);
    auto fresh = [&] { return YAML::Node(next_is_index ? YAML::NodeType::Sequence : YAML::NodeType::Map); };
    if (parent.IsSequence() && is_index(parts[i])) {
      size_t k = std::stoul(parts[i]);
      while (parent.size() <= k) parent.push_back(fresh());
      // An item that is not a section becomes one, as a key's value does below (found by the fuzzer).
      if (!(parent[k].IsMap() || parent[k].IsSequence())) parent[k] = fresh();
      chain.push_back(parent[k]);
      continue;
    }
    YAML::Node next = parent[parts[i]];
    if (!next.IsDefined() || !(next.IsMap() || next.IsSequence())) {
      parent[parts[i]] = fresh();
      next = parent[parts[i]];
    }
    chain.push_back(next);
  }
  YAML::Node last = chain.back();
  if (last.IsSequence() && is_index(parts.back())) {
    size_t k = std::stoul(parts.back());
    while (last.size() <= k) last.push_back(YAML::Node());
    last[k] = value;
  } else {
    last[parts.back()] = value;
  }
}

// yaml-cpp keeps both entries of a key written twice, and lookups find the first: a
// recipe that sets a key twice is refused instead. So is a key that is not a plain name
// (YAML allows `? [1, 2]: x`), a node that holds itself through an alias (`a: &x {b: *x}`,
// which every reader would follow forever) and aliases that multiply a small file into a
// huge tree (each alias of an alias doubles it): all three found by the fuzzer.
struct KeyWalk {
  const std::string& file;
  std::vector<YAML::Node> ancestors;  // the path from the root, to tell a cycle
  size_t visited = 0;

  void walk(const YAML::Node& node, const std::string& prefix) {
    constexpr size_t kMaxNodes = 100000;  // the largest recipe shipped holds a few hundred
    if (++visited > kMaxNodes)
      throw Error(file + ": more than " + std::to_string(kMaxNodes) + " values once its aliases are expanded");
    if (!node.IsMap() && !node.IsSequence()) return;
    for (const YAML::Node& above : ancestors)
      if (node.is(above))
        throw Error(file + ": key '" + (prefix.empty() ? std::string("(top)") : prefix) +
                    "' holds itself through a YAML alias");
    ancestors.push_back(node);
    if (node.IsMap()) {
      std::set<std::string> seen;
      for (const auto& kv : node) {
        if (!kv.first.IsScalar())
          throw Error(file + ": a key " + (prefix.empty() ? "at the top" : "under '" + prefix + "'") +
                      " is not a plain name");
        const std::string key = kv.first.Scalar(), path = prefix.empty() ? key : prefix + "." + key;
        if (!seen.insert(key).second) throw Error(file + ": key '" + path + "' is given twice");
        walk(kv.second, path);
      }
    } else {
      for (size_t i = 0; i < node.size(); ++i) walk(node[i], prefix + "." + std::to_string(i));
    }
    ancestors.pop_back();
  }
};

void refuse_bad_keys(const YAML::Node& node, const std::string& file) { KeyWalk{file, {}}.walk(node, ""); }

void collect_leaves(const YAML::Node& node, const std::string& prefix, std::vector<std::string>& out) {
  if (node.IsMap() && node.size() > 0) {
    for (const auto& kv : node)
      collect_leaves(kv.second, prefix.empty() ? kv.first.as<std::string>()
                                               : prefix + "." + kv.first.as<std::string>(), out);
  } else if (node.IsSequence() && node.size() > 0 && node[0].IsMap()) {
    for (size_t i = 0; i < node.size(); ++i) collect_leaves(node[i], prefix + "." + std::to_string(i), out);
  } else if (!prefix.empty()) {  // an empty document has no keys
    out.push_back(prefix);
  }
}

}  // namespace

std::optional<YAML::Node> Section::lookup(const std::string& full_key) const {
  // reset() rebinds a handle; operator= would overwrite the node it points at.
  YAML::Node node;
  node.reset(s_->tree);
  for (const auto& part : split_key(full_key)) {
    const YAML::Node& parent = node;
    if (parent.IsSequence() && is_index(part)) {
      size_t i = std::stoul(part);
      if (i >= parent.size()) return std::nullopt;
      YAML::Node child = parent[i];
      node.reset(child);
    } else if (parent.IsMap()) {
      YAML::Node child = parent[part];
      if (!child.IsDefined() || child.IsNull()) return std::nullopt;
      node.reset(child);
    } else {
      return std::nullopt;
    }
  }
  return node;
}

std::optional<YAML::Node> Section::lookup_value(const std::string& full_key) const {
  auto node = lookup(full_key);
  if (node) return node;
  // Present but empty (`key:` or `--set key=`)?
  const auto parts = split_key(full_key);
  std::string parent;
  for (size_t i = 0; i + 1 < parts.size(); ++i) parent += (i ? "." : "") + parts[i];
  auto above = parent.empty() ? std::optional<YAML::Node>(s_->tree) : lookup(parent);
  if (above && above->IsMap()) {
    YAML::Node child = (*above)[parts.back()];
    if (child.IsDefined() && child.IsNull()) throw Error(s_->file + ": key '" + full_key + "' has no value");
  }
  return std::nullopt;
}

namespace {
std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}
}  // namespace

std::string Range::text() const {
  const bool low = std::isfinite(lo), high = std::isfinite(hi);
  if (low && high) return std::string("in ") + (lo_open ? "(" : "[") + number_text(lo) + ", " + number_text(hi) + (hi_open ? ")" : "]");
  if (low) return (lo_open ? "> " : ">= ") + number_text(lo);
  if (high) return (hi_open ? "< " : "<= ") + number_text(hi);
  return "any";
}

void Section::refuse(const std::string& k, double value, const Range& range, bool each) const {
  throw Error(s_->file + ": key '" + k + "' must " + (each ? "hold numbers " : "be ") + range.text() + ", got " +
              number_text(value));
}

std::string Section::choice(const std::string& key, const std::string& fallback,
                            const std::vector<std::string>& choices) const {
  const std::string value = get(key, fallback);
  std::string listed;
  for (size_t i = 0; i < choices.size(); ++i) listed += (i ? ", " : "") + choices[i];
  s_->rules[full(key)].accepts = "one of " + listed;
  if (std::find(choices.begin(), choices.end(), value) == choices.end())
    throw Error(s_->file + ": key '" + full(key) + "' must be one of " + listed + ", got '" + value + "'");
  return value;
}

void Section::record(const std::string& full_key, const YAML::Node& value) const {
  s_->read.insert(full_key);
  set_path(s_->resolved, split_key(full_key), value);
}

bool Section::has(const std::string& key) const { return lookup(full(key)).has_value(); }

bool Section::is_sequence(const std::string& key) const {
  auto node = lookup(full(key));
  return node && node->IsSequence();
}

std::vector<std::string> Section::keys() const {
  std::vector<std::string> out;
  auto node = prefix_.empty() ? std::optional<YAML::Node>(s_->tree) : lookup(prefix_);
  if (node && node->IsMap())
    for (const auto& kv : *node) out.push_back(kv.first.as<std::string>());
  return out;
}

std::vector<Section> Section::items(const std::string& key) const {
  std::string k = full(key);
  s_->read.insert(k);
  std::vector<Section> out;
  auto node = lookup(k);
  if (!node) return out;
  if (!node->IsSequence()) throw Error(s_->file + ": key '" + k + "' should be a list");
  for (size_t i = 0; i < node->size(); ++i) {
    if (!(*node)[i].IsMap()) throw Error(s_->file + ": key '" + k + "." + std::to_string(i) + "' should be a mapping");
    out.push_back(Section(s_, k + "." + std::to_string(i)));
  }
  return out;
}

Section Section::sub(const std::string& key) const {
  std::string k = full(key);
  auto node = lookup(k);
  if (node && !node->IsMap())
    throw Error(s_->file + ": key '" + k + "' should be a mapping of keys");
  s_->read.insert(k);  // an empty section is fine
  return Section(s_, k);
}

Error Section::error(const std::string& key, const std::string& msg) const {
  return Error(s_->file + ": key '" + full(key) + "': " + msg);
}

Recipe Recipe::parse(const std::string& text, const std::string& name,
                     const std::vector<std::string>& overrides) {
  auto s = std::make_shared<Section::State>();
  s->file = name;
  try {
    s->tree = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(name + ": malformed YAML at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (s->tree.IsNull()) s->tree = YAML::Node(YAML::NodeType::Map);
  if (!s->tree.IsMap()) throw Error(name + ": a recipe must be a mapping of keys");
  s->resolved = YAML::Node(YAML::NodeType::Map);
  for (const auto& o : overrides) {
    auto eq = o.find('=');
    if (eq == std::string::npos || eq == 0)
      throw Error("--set " + o + ": expected key=value");
    std::string key = o.substr(0, eq);
    if (key.front() == '.' || key.back() == '.' || key.find("..") != std::string::npos)
      throw Error("--set " + o + ": '" + key + "' is not a key (parts are separated by single dots)");
    YAML::Node value;
    try {
      value = YAML::Load(o.substr(eq + 1));
    } catch (const YAML::Exception& e) {
      throw Error("--set " + o + ": malformed value: " + e.msg);
    }
    set_path(s->tree, split_key(key), value);
    s->overridden.insert(key);
  }
  refuse_bad_keys(s->tree, name);  // the overrides' values included
  return Recipe(s);
}

Recipe Recipe::load(const std::string& file, const std::vector<std::string>& overrides) {
  std::ifstream in(file);
  if (!in) throw Error(file + ": cannot read recipe (no such file?)");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse(ss.str(), file, overrides);
}

namespace {
void merge_into(YAML::Node base, const YAML::Node& over) {
  for (const auto& kv : over) {
    const std::string key = kv.first.Scalar();
    YAML::Node mine = base[key];
    if (mine.IsDefined() && mine.IsMap() && kv.second.IsMap()) merge_into(mine, kv.second);
    else base[key] = YAML::Clone(kv.second);
  }
}
// Adds to `base` what it lacks of `from`: the reverse of merge_into.
void fill_into(YAML::Node base, const YAML::Node& from) {
  for (const auto& kv : from) {
    const std::string key = kv.first.Scalar();
    YAML::Node mine = base[key];
    if (!mine.IsDefined() || mine.IsNull()) base[key] = YAML::Clone(kv.second);
    else if (mine.IsMap() && kv.second.IsMap()) fill_into(mine, kv.second);
  }
}
}  // namespace

Section Section::filled_from(const Section& base) const {
  auto mine = lookup(prefix_);
  auto theirs = base.prefix_.empty() ? std::optional<YAML::Node>(base.s_->tree) : base.lookup(base.prefix_);
  if (!mine || !mine->IsMap()) throw Error(s_->file + ": key '" + prefix_ + "' should be a mapping of keys");
  if (theirs && theirs->IsMap()) fill_into(*mine, *theirs);
  return *this;
}

std::vector<YAML::Node> Recipe::stages() const {
  std::vector<YAML::Node> out;
  const YAML::Node list = s_->tree["stages"];
  if (!list.IsDefined()) return out;
  if (!list.IsSequence() || list.size() == 0)
    throw Error(s_->file + ": key 'stages' must be a non-empty list of stages");
  for (size_t i = 0; i < list.size(); ++i) {
    if (!list[i].IsMap())
      throw Error(s_->file + ": key 'stages." + std::to_string(i) + "' must be a mapping of keys");
    out.push_back(list[i]);
  }
  return out;
}

Recipe Recipe::with_overrides(const YAML::Node& overrides, const std::string& name,
                              const std::vector<std::string>& without) const {
  YAML::Node tree = YAML::Clone(s_->tree);
  tree.remove("stages");
  for (const auto& key : without) tree.remove(key);
  if (overrides.IsMap()) merge_into(tree, overrides);
  YAML::Emitter e;
  e << tree;
  return parse(e.c_str(), name);
}

Section Recipe::root() const { return Section(s_, ""); }
const std::string& Recipe::file() const { return s_->file; }

void Recipe::reject_unknown() const {
  std::vector<std::string> leaves;
  collect_leaves(s_->tree, "", leaves);
  for (const auto& leaf : leaves) {
    if (s_->read.count(leaf)) continue;
    std::string best;
    size_t best_d = 4;
    for (const auto& known : s_->read) {
      size_t d = edit_distance(leaf, known);
      if (d < best_d) best_d = d, best = known;
    }
    std::string origin = s_->overridden.count(leaf) ? " (from --set)" : "";
    throw Error(s_->file + ": unknown key '" + leaf + "'" + origin +
                (best.empty() ? "" : "; did you mean '" + best + "'?"));
  }
}

const std::set<std::string>& Recipe::defaulted_keys() const { return s_->defaulted; }

const std::map<std::string, KeyRule>& Recipe::key_rules() const { return s_->rules; }

std::string Recipe::resolved_yaml() const {
  YAML::Emitter e;
  e.SetDoublePrecision(15);  // 0.2, not 0.20000000000000001
  e.SetFloatPrecision(7);
  e << s_->resolved;
  return std::string(e.c_str()) + "\n";
}

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] != b[j - 1])});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace segue
