#pragma once
// YAML recipes with strict key checking. Code declares the keys it understands by
// reading them (with a default, or required); after everything is read,
// reject_unknown() refuses any key nobody read, which catches typos like "ppo.lrr".
// The values actually used, defaults included, form the resolved recipe that a run
// directory records.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"

namespace segue {

class Recipe;

// A view of one mapping inside a recipe, e.g. the "ppo" section.
class Section {
 public:
  template <class T>
  T get(const std::string& key, const T& fallback) const;
  template <class T>
  T require(const std::string& key) const;
  bool has(const std::string& key) const;
  bool is_sequence(const std::string& key) const;
  Section sub(const std::string& key) const;
  // The keys of this mapping, in document order.
  std::vector<std::string> keys() const;
  // The mappings of the sequence `key` (absent: none), each a Section "key.i".
  std::vector<Section> items(const std::string& key) const;
  const std::string& path() const { return prefix_; }
  // "FILE: key 'a.b': msg" — the one-line error for a bad value found after reading.
  Error error(const std::string& key, const std::string& msg) const;
  // A network's hidden layer widths (`pi_hidden: [64, 64]`): a list of positive integers.
  std::vector<int> layers(const std::string& key, const std::vector<int>& fallback) const;

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
  // The keys among them that the recipe left to their defaults ("ppo.noise_repeat").
  const std::set<std::string>& defaulted_keys() const;
  // The recipe's `stages:` list (a curriculum), each item as written (empty: none).
  std::vector<YAML::Node> stages() const;
  // This recipe without its stages, with `overrides` laid over it (mappings merged key by
  // key, any other value replaced): one stage of a curriculum, named `name` in errors.
  Recipe with_overrides(const YAML::Node& overrides, const std::string& name) const;

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
};

template <class T>
T Section::get(const std::string& key, const T& fallback) const {
  std::string k = full(key);
  auto node = lookup_value(k);
  T value = node ? convert<T>(*node, k) : fallback;
  if (!node) s_->defaulted.insert(k);
  record(k, YAML::Node(value));
  return value;
}

template <class T>
T Section::require(const std::string& key) const {
  std::string k = full(key);
  auto node = lookup_value(k);
  if (!node) throw Error(s_->file + ": missing required key '" + k + "'");
  T value = convert<T>(*node, k);
  record(k, YAML::Node(value));
  return value;
}

// Type names for messages.
template <class T> const char* type_name();

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

}  // namespace segue
