#pragma once
// YAML recipes with strict key checking. Code declares the keys it understands by
// reading them (with a default, or required, and the values a number may take); after
// everything is read, reject_unknown() refuses any key nobody read, which catches typos
// like "ppo.lrr". The values actually used, defaults included, form the resolved recipe
// that a run directory records; each key's type and range, declared where it is read,
// form the table the recipe reference (docs/recipes.md, `segue keys`) is printed from.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"

namespace segue {

class Recipe;

// The values a number (or each number of a list) may take, checked where its key is read.
struct Range {
  double lo = -HUGE_VAL, hi = HUGE_VAL;
  bool lo_open = false, hi_open = false;
  static Range any() { return {}; }
  static Range positive() { return {0, HUGE_VAL, true, false}; }
  static Range non_negative() { return {0, HUGE_VAL, false, false}; }
  static Range at_least(double lo) { return {lo, HUGE_VAL, false, false}; }
  static Range at_most(double hi) { return {-HUGE_VAL, hi, false, false}; }
  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Range open_closed(double lo, double hi) { return {lo, hi, true, false}; }
  bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  std::string text() const;  // "> 0", "in (0, 1]", "any"
};

// What the reference lists for a key: its type, and what it accepts ("" where undeclared).
struct KeyRule {
  std::string type, accepts;
};

// A view of one mapping inside a recipe, e.g. the "ppo" section.
class Section {
 public:
  template <class T>
  T get(const std::string& key, const T& fallback) const;
  // A number, or a list of numbers, refused unless (each) in `range`.
  template <class T>
  T get(const std::string& key, const T& fallback, const Range& range) const;
  template <class T>
  T require(const std::string& key) const;
  template <class T>
  T require(const std::string& key, const Range& range) const;
  // A string that must be one of `choices`.
  std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& choices) const;
  bool has(const std::string& key) const;
  bool is_sequence(const std::string& key) const;
  Section sub(const std::string& key) const;
  // The keys of this mapping, in document order.
  std::vector<std::string> keys() const;
  // The mappings of the sequence `key` (absent: none), each a Section "key.i".
  std::vector<Section> items(const std::string& key) const;
  // This mapping with the keys it leaves out filled in from `base` as written there
  // (mappings key by key): a variant of another section, read in full at its own keys, e.g.
  // a transition's training env over the recipe's `env:`.
  Section filled_from(const Section& base) const;
  const std::string& path() const { return prefix_; }
  // "FILE: key 'a.b': msg" — the one-line error for a bad value found after reading.
  Error error(const std::string& key, const std::string& msg) const;
  // A network's hidden layer widths (`pi_hidden: [64, 64]`): a list of positive integers.
  std::vector<int> layers(const std::string& key, const std::vector<int>& fallback) const {
    return get(key, fallback, Range::at_least(1));
  }

 private:
  friend class Recipe;
  struct State;
  Section(std::shared_ptr<State> s, std::string prefix) : s_(std::move(s)), prefix_(std::move(prefix)) {}
  std::string full(const std::string& key) const {
    return prefix_.empty() ? key : key.empty() ? prefix_ : prefix_ + "." + key;
  }
  // The value at full_key, if present; a key written with no value is refused (a
  // `--set ppo.total_steps=` must not silently become the default).
  std::optional<YAML::Node> lookup(const std::string& full_key) const;
  std::optional<YAML::Node> lookup_value(const std::string& full_key) const;
  template <class T>
  T convert(const YAML::Node& node, const std::string& full_key) const;
  void record(const std::string& full_key, const YAML::Node& value) const;
  template <class T>
  void note_type(const std::string& full_key) const;
  template <class T>
  void check(const std::string& full_key, const T& value, const Range& range, bool given) const;
  void refuse(const std::string& full_key, double value, const Range& range, bool each) const;
  std::shared_ptr<State> s_;
  std::string prefix_;
};

class Recipe {
 public:
  // Loads FILE and applies "key=value" overrides (values parsed as YAML).
  static Recipe load(const std::string& file, const std::vector<std::string>& overrides = {});
  static Recipe parse(const std::string& yaml_text, const std::string& name,
                      const std::vector<std::string>& overrides = {});
  Section root() const;
  const std::string& file() const;
  void reject_unknown() const;
  // The values read so far, defaults included, as YAML text.
  std::string resolved_yaml() const;
  // The keys among them that the recipe left to their defaults ("ppo.min_log_std").
  const std::set<std::string>& defaulted_keys() const;
  // Each key read so far with its type and range ("transitions.0.max_steps": items by index).
  const std::map<std::string, KeyRule>& key_rules() const;
  // The recipe's `stages:` list (a curriculum), each item as written (empty: none).
  std::vector<YAML::Node> stages() const;
  // This recipe without its stages and its top-level keys `without`, with `overrides` laid
  // over it (mappings merged key by key, any other value replaced): one stage of a
  // curriculum, named `name` in errors.
  Recipe with_overrides(const YAML::Node& overrides, const std::string& name,
                        const std::vector<std::string>& without = {}) const;

 private:
  explicit Recipe(std::shared_ptr<Section::State> s) : s_(std::move(s)) {}
  std::shared_ptr<Section::State> s_;
};

struct Section::State {
  std::string file;
  YAML::Node tree;
  YAML::Node resolved;
  std::set<std::string> read;
  std::set<std::string> overridden;
  std::set<std::string> defaulted;  // keys read whose value is the code's default
  std::map<std::string, KeyRule> rules;
};

// Type names for messages.
template <class T> const char* type_name();

template <class T>
void Section::note_type(const std::string& k) const {
  KeyRule& rule = s_->rules[k];
  rule.type = type_name<T>();
  if constexpr (std::is_unsigned_v<T> && !std::is_same_v<T, bool>) {
    if (rule.accepts.empty()) rule.accepts = ">= 0";  // the conversion refuses the rest
  }
}

template <class T>
void Section::check(const std::string& k, const T& value, const Range& range, bool given) const {
  constexpr bool number = std::is_arithmetic_v<T> && !std::is_same_v<T, bool>;
  static_assert(number || std::is_same_v<T, std::vector<int>> || std::is_same_v<T, std::vector<double>>,
                "a Range applies to numbers and lists of numbers");
  s_->rules[k].accepts = (number || range.text() == "any" ? "" : "each ") + range.text();
  if (!given) return;
  if constexpr (number) {
    if (!range.contains(double(value))) refuse(k, double(value), range, false);
  } else {
    for (auto v : value)
      if (!range.contains(double(v))) refuse(k, double(v), range, true);
  }
}

template <class T>
T Section::get(const std::string& key, const T& fallback) const {
  std::string k = full(key);
  auto node = lookup_value(k);
  T value = node ? convert<T>(*node, k) : fallback;
  if (!node) s_->defaulted.insert(k);
  note_type<T>(k);
  record(k, YAML::Node(value));
  return value;
}

template <class T>
T Section::get(const std::string& key, const T& fallback, const Range& range) const {
  T value = get(key, fallback);
  // The code's own default may stand outside the range (NaN for "not set").
  check(full(key), value, range, /*given=*/!s_->defaulted.count(full(key)));
  return value;
}

template <class T>
T Section::require(const std::string& key) const {
  std::string k = full(key);
  auto node = lookup_value(k);
  if (!node) throw Error(s_->file + ": missing required key '" + k + "'");
  T value = convert<T>(*node, k);
  note_type<T>(k);
  record(k, YAML::Node(value));
  return value;
}

template <class T>
T Section::require(const std::string& key, const Range& range) const {
  T value = require<T>(key);
  check(full(key), value, range, true);
  return value;
}

template <class T>
T Section::convert(const YAML::Node& node, const std::string& k) const {
  auto bad = [&]() {
    YAML::Emitter e;
    e << YAML::Flow << node;
    return Error(s_->file + ": key '" + k + "' expects " + type_name<T>() + ", got '" +
                 e.c_str() + "'");
  };
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    // Accept 2e6 for an integer: step budgets are naturally written that way.
    if (!node.IsScalar()) throw bad();
    double d;
    try { d = node.as<double>(); } catch (const YAML::Exception&) { throw bad(); }
    // In range before the cast (a cast out of range is undefined; found by the fuzzer).
    constexpr double hi = double(uint64_t(1) << (std::numeric_limits<T>::digits - 1)) * 2.0;  // 2^digits
    constexpr double lo = std::is_signed_v<T> ? -hi : 0.0;
    if (!(d >= lo && d < hi) || d != static_cast<double>(static_cast<T>(d))) throw bad();
    return static_cast<T>(d);
  } else {
    T value;
    try { value = node.as<T>(); } catch (const YAML::Exception&) { throw bad(); }
    // NaN and infinity pass every range check (NaN compares false): refuse them here.
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(value)) throw Error(s_->file + ": key '" + k + "' must be a finite number, got " + node.Scalar());
    } else if constexpr (std::is_same_v<T, std::vector<double>>) {
      for (size_t i = 0; i < value.size(); ++i)
        if (!std::isfinite(value[i]))
          throw Error(s_->file + ": key '" + k + "' must hold finite numbers, got " + node[i].Scalar());
    }
    return value;
  }
}

// Levenshtein distance: how a typo is matched to the name it meant ("did you mean").
size_t edit_distance(const std::string& a, const std::string& b);

}  // namespace segue
