#!/usr/bin/env python3
"""Writes the model file of an N-link chain of unit point masses on
massless unit rods, hinged to a base that vibrates vertically, for the
size checks of docs/building.md ("Large models"). Plain Python.

    python3 benches/added_models/chain.py 20 chain20 > models/chain20.toml
"""
import sys

n = int(sys.argv[1])
name = sys.argv[2] if len(sys.argv) > 2 else f"chain{n}"
kinetic = " + ".join(f"m*(dot(x{i})^2 + dot(z{i})^2)/2" for i in range(1, n + 1))
potential = "g*m*(" + " + ".join(f"z{i}" for i in range(1, n + 1)) + ")"
lines = [
    f"# A {n}-link chain of unit point masses on a vertically vibrating base",
    "# (written for the size check); angles from the upward vertical.",
    f'name = "{name}"',
    f'description = "{n}-link pendulum on a vertically vibrating base"',
    f'lagrangian = "{kinetic} - {potential}"',
    "",
]
for i in range(1, n + 1):
    lines += ["[[coordinates]]", f'name = "phi{i}"', f'velocity = "phi{i}d"', "periodic = true", ""]
for p, v in [("m", 1.0), ("l", 1.0), ("g", 1.0), ("a", 5.0), ("nu", 100.0)]:
    lines += ["[[parameters]]", f'name = "{p}"', f'description = "{p}"', f"default = {v}", ""]
lines += ["[fast_phase]", 'name = "tau"', 'rate = "nu"', 'amplitude = "a"', "", "[definitions]"]
lines.append('base_z = "a/nu*cos(tau)"')
for i in range(1, n + 1):
    x_before = f"x{i - 1} + " if i > 1 else ""
    z_before = f"z{i - 1}" if i > 1 else "base_z"
    lines += [f'x{i} = "{x_before}l*sin(phi{i})"', f'z{i} = "{z_before} + l*cos(phi{i})"']
print("\n".join(lines))
