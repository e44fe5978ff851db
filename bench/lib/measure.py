"""Runs one command of a bench as its own process and records what it cost.

Usage: python3 bench/lib/measure.py OUT COMMAND...
Writes the command's output to OUT.log and {"exit", "wall_s", "cpu_s", "peak_kib"} to OUT.json
(CPU seconds and peak resident KiB of its largest process, from getrusage of the children);
exits non-zero, naming OUT.log, when the command fails.
"""
import json
import resource
import subprocess
import sys
import time

out, cmd = sys.argv[1], sys.argv[2:]
start = time.monotonic()
with open(out + ".log", "w") as log:
    code = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT).returncode
usage = resource.getrusage(resource.RUSAGE_CHILDREN)
json.dump({"exit": code, "wall_s": time.monotonic() - start,
           "cpu_s": usage.ru_utime + usage.ru_stime, "peak_kib": usage.ru_maxrss},
          open(out + ".json", "w"))
if code != 0:
    sys.exit(f"{' '.join(cmd[:3])} failed (exit {code}); see {out}.log")
