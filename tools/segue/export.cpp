// segue export CHECKPOINT OUT.pt: the policy as TorchScript for torch.jit.load.
#include <cstdio>

#include "algorithms/policy.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {

const Command kExport{
    "export",
    "CHECKPOINT OUT.pt",
    "Writes the deterministic policy of a training checkpoint as TorchScript:\n"
    "forward(obs[B, obs_dim]) -> action[B, act_dim] in the environment's units,\n"
    "observation normalisation included; methods obs_dim() and act_dim().",
    {"CHECKPOINT", "OUT.pt"},
    {}};

}  // namespace

int export_main(int argc, char** argv) {
  Args args(kExport, argc, argv);
  if (args.help()) return print_help(kExport);
  Policy p = Policy::load(args.positional(0));
  p.export_torchscript(args.positional(1));
  std::printf("wrote %s (obs_dim %d, act_dim %d)\n", args.positional(1).c_str(), p.obs_dim(), p.act_dim());
  return 0;
}

}  // namespace segue::cli
