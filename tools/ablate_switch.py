#!/usr/bin/env python3
"""Which switch Q-network helps or hurts: With TP + Q with q_ab kept on one transition only
(the others replaced by a Q-network that always stays, i.e. With TP there), and with none
kept (which must equal With TP). Uses the shipped artefacts of TASK.

usage: /usr/bin/python3 tools/ablate_switch.py TASK [--episodes 50] [--seed 0] [--group walker]
"""
import argparse, json, os, shutil, subprocess, tempfile

import torch

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ap = argparse.ArgumentParser()
ap.add_argument("task")
ap.add_argument("--episodes", type=int, default=50)
ap.add_argument("--seed", type=int, default=0)
ap.add_argument("--group", default="walker")
args = ap.parse_args()

src = os.path.join(root, "assets", "policies", args.group, args.task)
names = sorted(d for d in os.listdir(src) if os.path.isfile(os.path.join(src, d, "q.pt")))


def always_stay(path):
    m = torch.jit.load(path)
    last = max(int(k[1:]) for k, _ in m.named_buffers() if k[0] == "w" and k[1:].isdigit())
    setattr(m, f"w{last}", torch.zeros_like(getattr(m, f"w{last}")))
    setattr(m, f"b{last}", torch.tensor([1.0, 0.0]))  # Q(stay) > Q(switch) everywhere
    m.save(path)


def evaluate(keep):
    with tempfile.TemporaryDirectory() as tmp:
        dst = os.path.join(tmp, "t")
        shutil.copytree(src, dst)
        for n in names:
            if n != keep:
                always_stay(os.path.join(dst, n, "q.pt"))
        out = subprocess.run([os.path.join(root, "build", "segue"), "eval", "--task", args.task, "--method", "tp+q",
                              "--episodes", str(args.episodes), "--seed", str(args.seed), "--json",
                              "--set", f"methods.transitions={dst}"], check=True, capture_output=True, text=True)
        return json.loads(out.stdout.strip().splitlines()[-1])["success_count_mean"]


print(f"{args.task}, With TP + Q, {args.episodes} episodes, seed {args.seed}: success count")
print(f"  no q_ab kept (= With TP): {evaluate(None):.2f}")
for n in names:
    print(f"  only {n}'s q_ab kept: {evaluate(n):.2f}")
