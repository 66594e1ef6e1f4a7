#!/usr/bin/env python3
"""Independent oracle for the matching tests: min-cost maximum-cardinality matching by
NetworkX's max_weight_matching(maxcardinality=True).

Input file: first line "num_nodes num_edges", then "u v cost_nanos" per edge (integer costs
in units of 1e-9). Prints: "<number of pairs> <total cost in nanos>".
Exit code 3 when networkx is missing (the test skips).
"""
import sys

try:
    import networkx as nx
except ImportError:
    sys.exit(3)


def main(path):
    with open(path) as f:
        n, m = map(int, f.readline().split())
        edges = [tuple(map(int, f.readline().split())) for _ in range(m)]
    big = max((c for _, _, c in edges), default=0) + 1
    g = nx.Graph()
    g.add_nodes_from(range(n))
    for u, v, c in edges:
        # Integer weights: exact arithmetic inside networkx. Larger weight = smaller cost.
        w = big - c
        if g.has_edge(u, v):
            w = max(w, g[u][v]["weight"])
        g.add_edge(u, v, weight=w)
    matching = nx.max_weight_matching(g, maxcardinality=True)
    cost = {}
    for u, v, c in edges:
        key = (min(u, v), max(u, v))
        cost[key] = min(c, cost.get(key, c))
    total = sum(cost[(min(u, v), max(u, v))] for u, v in matching)
    print(len(matching), total)


if __name__ == "__main__":
    main(sys.argv[1])
