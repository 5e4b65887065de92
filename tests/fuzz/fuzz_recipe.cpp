// libFuzzer target for the recipe loader and the --set parser (core/recipe.h): the input's
// first line holds `--set` overrides separated by ';', the rest is the recipe's YAML. Every
// key the recipe holds is then read as each type a reader asks for. The only exception a
// bad input may raise is segue::Error (one line for the user); anything else, a crash, a
// hang or a sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/recipe.h"

namespace {

// Reads every key under `s` as the readers do: integers, numbers, text, switches, lists,
// layer widths, nested sections and lists of sections.
void read_all(const segue::Section& s, int depth) {
  if (depth > 8) return;
  for (const std::string& key : s.keys()) {
    auto attempt = [](auto&& read) {
      try {
        read();
      } catch (const segue::Error&) {
      }
    };
    attempt([&] { s.get<int>(key, 0); });
    attempt([&] { s.get<int64_t>(key, 0); });
    attempt([&] { s.get<double>(key, 0.0); });
    attempt([&] { s.get<bool>(key, false); });
    attempt([&] { s.get<std::string>(key, ""); });
    attempt([&] { s.get<std::vector<double>>(key, {}); });
    attempt([&] { s.get<std::vector<std::string>>(key, {}); });
    attempt([&] { s.layers(key, {32}); });
    attempt([&] { s.require<double>(key); });
    attempt([&] { s.is_sequence(key); });
    attempt([&] {
      for (const segue::Section& item : s.items(key)) read_all(item, depth + 1);
    });
    attempt([&] { read_all(s.sub(key), depth + 1); });
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const size_t newline = input.find('\n');
  const std::string first = input.substr(0, newline), yaml = newline == std::string::npos ? "" : input.substr(newline + 1);
  std::vector<std::string> sets;
  for (size_t at = 0; at <= first.size();) {
    const size_t end = std::min(first.find(';', at), first.size());
    if (end > at) sets.push_back(first.substr(at, end - at));
    at = end + 1;
  }
  try {
    segue::Recipe r = segue::Recipe::parse(yaml, "fuzz.yaml", sets);
    read_all(r.root(), 0);
    // A section filled from `env:` (as a transition's training.env is), then read in full.
    for (const std::string& key : r.root().keys()) {
      try {
        read_all(r.root().sub(key).filled_from(r.root().sub("env")), 1);
      } catch (const segue::Error&) {
      }
    }
    r.resolved_yaml();
    for (const auto& stage : r.stages()) {
      try {
        read_all(r.with_overrides(stage, "fuzz.yaml (stage)").root(), 0);
      } catch (const segue::Error&) {
      }
    }
    r.reject_unknown();
  } catch (const segue::Error&) {
  }
  return 0;
}
