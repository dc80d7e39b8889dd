"""Snippets from the Rosie kit page (000_5f76ade803e16979.txt), as the kit README carries
them; shared by the tests that run them inside built kits."""

# The page's ik_cases check, verbatim apart from the page's lost indentation of continued lines.
IK_CASES_SNIPPET = """
import json
import numpy as np
doc = json.load(open("ik_cases.json"))
def rot(axis, q):
    x, y, z = axis
    c, s, t = np.cos(q), np.sin(q), 1 - np.cos(q)
    return np.array([[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
[t * x * y + s * z, t * y * y + c, t * y * z - s * x],
[t * x * z - s * y, t * y * z + s * x, t * z * z + c]])
def fk(q):
    T = np.eye(4)
    for j, qi in zip(doc["chain"]["joints"], q):
        A = np.eye(4)
        A[:3, 3], A[:3, :3] = j["origin_xyz"], rot(j["axis"], qi)
        T = T @ A
    return T @ np.diag([1, -1, -1, 1]) # tool0: link_6 turned 180 deg about x
worst = 0.0
for case in doc["cases"]:
    for sol in [case["expected"]] + case["all_solutions"]:
        T = fk(sol["q"])
        worst = max(worst, np.abs(T[:3, 3] - case["target"]["xyz"]).max(),
np.abs(T[:3, :3] - case["target"]["rotation"]).max())
print(len(doc["cases"]), "cases, worst error", worst, "tolerance", doc["tolerance"]["position_m"])
"""
