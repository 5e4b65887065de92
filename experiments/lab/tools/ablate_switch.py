#!/usr/bin/env python3
"""Which switch Q-network helps or hurts: With TP + Q with q_ab kept on one transition only
(the others replaced by a Q-network that always stays, i.e. With TP there), and with none
kept (which must equal With TP). With --margins, instead: every q_ab kept, switching only
where Q(switch) > Q(stay) + margin (a large margin is With TP). Uses the shipped artefacts
of TASK, or those of a run directory (--dir runs/TASK). Only the last layer's bias of the
exported q.pt files (copies) is changed.

usage: /usr/bin/python3 tools/ablate_switch.py TASK [--episodes 50] [--seed 0] [--group walker] [--dir DIR]
                                               [--margins 0 0.2 0.4]
"""
import argparse, json, os, shutil, subprocess, tempfile

import torch

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ap = argparse.ArgumentParser()
ap.add_argument("task")
ap.add_argument("--episodes", type=int, default=50)
ap.add_argument("--seed", type=int, default=0)
ap.add_argument("--group", default="walker")
ap.add_argument("--dir", help="a run directory to take the artefacts from instead")
ap.add_argument("--margins", type=float, nargs="+", help="evaluate these switch margins instead")
args = ap.parse_args()

src = os.path.abspath(args.dir) if args.dir else os.path.join(root, "assets", "policies", args.group, args.task)
names = sorted(d for d in os.listdir(src) if os.path.isfile(os.path.join(src, d, "q.pt")))


def edit_last_layer(path, always_stay=False, margin=0.0):
    m = torch.jit.load(path)
    last = max(int(k[1:]) for k, _ in m.named_buffers() if k[0] == "w" and k[1:].isdigit())
    if always_stay:
        setattr(m, f"w{last}", torch.zeros_like(getattr(m, f"w{last}")))
        setattr(m, f"b{last}", torch.tensor([1.0, 0.0]))  # Q(stay) > Q(switch) everywhere
    else:
        b = getattr(m, f"b{last}").clone()
        b[0] += margin  # outputs are [Q(stay), Q(switch)], unscaled
        setattr(m, f"b{last}", b)
    m.save(path)


def evaluate(keep, margin=0.0):
    """keep: the transition whose q_ab is kept (the others always stay); None keeps all."""
    with tempfile.TemporaryDirectory() as tmp:
        dst = os.path.join(tmp, "t")
        for n in names:  # only what tp+q reads
            os.makedirs(os.path.join(dst, n))
            for f in ("policy.pt", "q.pt"):
                shutil.copy(os.path.join(src, n, f), os.path.join(dst, n, f))
            edit_last_layer(os.path.join(dst, n, "q.pt"), always_stay=keep is not None and n != keep, margin=margin)
        out = subprocess.run([os.path.join(root, "build", "segue"), "eval", "--task", args.task, "--method", "tp+q",
                              "--episodes", str(args.episodes), "--seed", str(args.seed), "--json",
                              "--set", f"methods.transitions={dst}"], check=True, capture_output=True, text=True)
        return json.loads(out.stdout.strip().splitlines()[-1])["success_count_mean"]


print(f"{args.task}, With TP + Q, {args.episodes} episodes, seed {args.seed}: success count")
if args.margins:
    for m in args.margins:
        print(f"  margin {m:g}: {evaluate(None, m):.2f}")
else:
    print(f"  no q_ab kept (= With TP): {evaluate(''):.2f}")
    for n in names:
        print(f"  only {n}'s q_ab kept: {evaluate(n):.2f}")
