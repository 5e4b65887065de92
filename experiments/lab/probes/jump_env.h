#pragma once
// The developer probes' walker_jump task, its env keys given on the command line as
// `segue --set` overrides of an empty task section (key=value ...). Exits with a one-line
// error on an unknown key or a bad value.
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "core/recipe.h"
#include "environments/registry.h"

inline std::unique_ptr<segue::Env> jump_env_from_args(int first, int argc, char** argv) {
  try {
    const segue::Recipe settings =
        segue::Recipe::parse("{}", "probe", std::vector<std::string>(argv + first, argv + argc));
    auto env = segue::task_factory("walker_jump", settings.root())();
    settings.reject_unknown();
    return env;
  } catch (const segue::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    std::exit(1);
  }
}
