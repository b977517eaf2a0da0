#!/usr/bin/env python3
"""Generates warehouse.json, the bundled warehouse topology (python3 standard library only,
deterministic: the same output on every run).

Layout (metres, vertices every 2 m along lanes and aisles):

    y = 31   P P P C P P ... parking spots and chargers on short spurs
    y = 28   <<<<<<<<<<<<<<<<<<<<<<<<<<<<<<<<  north lane, westbound   (one-way)
    y = 26   >>>>>>>>>>>>>>>>>>>>>>>>>>>>>>>>  north lane, eastbound   (one-way)
    y = 4-24 |  ^  v  ^  |  ^  v  ^  |  ...    16 aisles at x = 0, 4, ..., 60: one-way
                                                northbound (^) or southbound (v), every
                                                fourth two-way (|); rack positions in the
                                                aisles are stations
    y = 2    <<<<<<<<<<<<<<<<<<<<<<<<<<<<<<<<  south lane, westbound   (one-way)
    y = 0    >>>>>>>>>>>>>>>>>>>>>>>>>>>>>>>>  south lane, eastbound   (one-way)
    y = -3   S       S       S       S  ...    pick-and-drop stations on short spurs

The two lanes of a pair are joined both ways at every aisle, so every vertex can reach
every other. Footprints are generated: 1.2 m vertex squares and 1.4 m wide edges, so two
edges meeting at a right angle conflict (a turning vehicle sweeps the corner) while
parallel lanes 2 m apart do not. Partitions: "west" (x < 30 m) and "east" (x >= 30 m); an edge belongs to the
partition of its `from` vertex. Run from anywhere: it writes warehouse.json next to
itself (or to --output).
"""

import argparse
import json
import os

SPACING = 2.0          # m between consecutive vertices of a lane or aisle
AISLE_PITCH = 4.0      # m between aisle centre lines (a rack between neighbours)
AISLES = 16
LANE_LENGTH = AISLE_PITCH * (AISLES - 1)  # 60 m
AISLE_Y = (4.0, 24.0)  # first and last aisle vertex
SOUTH_LANES = (0.0, 2.0)   # eastbound, westbound
NORTH_LANES = (26.0, 28.0)  # eastbound, westbound
SPUR = 3.0             # m from a lane to a station, parking spot or charger
PARTITION_X = 30.0

LANE_SPEED = 2.0
AISLE_SPEED = 1.0
SPUR_SPEED = 0.5


def metres(value):
    """Whole metres as ints, so that the file reads 12 rather than 12.0."""
    return int(value) if float(value).is_integer() else value


class Plan:
    def __init__(self):
        self.vertices = []
        self.edges = []
        self.position = {}

    def vertex(self, vertex_id, x, y, kind="waypoint", **extra):
        entry = {"id": vertex_id, "x": metres(x), "y": metres(y), "kind": kind}
        entry.update(extra)
        entry["partition"] = "west" if x < PARTITION_X else "east"
        self.vertices.append(entry)
        self.position[vertex_id] = (x, y)
        return vertex_id

    def edge(self, start, end, max_speed, bidirectional=False, **extra):
        arrow = "<->" if bidirectional else "->"
        entry = {"id": start + arrow + end, "from": start, "to": end,
                 "bidirectional": bidirectional, "max_speed": max_speed}
        entry.update(extra)
        entry["partition"] = "west" if self.position[start][0] < PARTITION_X else "east"
        self.edges.append(entry)


def lane_id(name, x):
    return "lane-%s-%02d" % (name, x)


def lane_xs():
    count = int(LANE_LENGTH / SPACING) + 1
    return [int(i * SPACING) for i in range(count)]


def build():
    plan = Plan()
    xs = lane_xs()

    # Lanes: (name, y, direction of travel along x).
    lanes = [("s0", SOUTH_LANES[0], +1), ("s1", SOUTH_LANES[1], -1),
             ("n0", NORTH_LANES[0], +1), ("n1", NORTH_LANES[1], -1)]
    for name, y, _ in lanes:
        for x in xs:
            plan.vertex(lane_id(name, x), x, y)
    for name, _, direction in lanes:
        for left, right in zip(xs, xs[1:]):
            start, end = (left, right) if direction > 0 else (right, left)
            plan.edge(lane_id(name, start), lane_id(name, end), LANE_SPEED,
                      properties={"area": "lane"})

    # Aisles with rack positions (stations) at every other vertex past the aisle mouth.
    aisle_ys = [AISLE_Y[0] + SPACING * i
                for i in range(int((AISLE_Y[1] - AISLE_Y[0]) / SPACING) + 1)]
    for aisle in range(AISLES):
        x = int(aisle * AISLE_PITCH)
        ids = []
        for index, y in enumerate(aisle_ys):
            rack = 0 < index < len(aisle_ys) - 1 and index % 2 == 0
            ids.append(plan.vertex("aisle-%02d-y%02d" % (aisle, y), x, y,
                                   kind="station" if rack else "waypoint",
                                   properties={"aisle": str(aisle)}))
        two_way = aisle % 4 == 0
        northbound = aisle % 2 == 0
        chain = [lane_id("s1", x)] + ids + [lane_id("n0", x)]
        if not two_way and not northbound:
            chain.reverse()
        for start, end in zip(chain, chain[1:]):
            # Two-way aisles are narrow passing places: vehicles slow down there.
            restrictions = {"max_speed": 0.8} if two_way else None
            extra = {"restrictions": restrictions} if restrictions else {}
            plan.edge(start, end, AISLE_SPEED, bidirectional=two_way,
                      properties={"aisle": str(aisle)}, **extra)
        # The lanes of each pair are joined both ways at every aisle.
        plan.edge(lane_id("s0", x), lane_id("s1", x), LANE_SPEED, bidirectional=True)
        plan.edge(lane_id("n0", x), lane_id("n1", x), LANE_SPEED, bidirectional=True)

    # Pick-and-drop stations below the south lanes, every 8 m.
    for number, x in enumerate(range(2, int(LANE_LENGTH), 8), start=1):
        station = plan.vertex("station-%02d" % number, x, SOUTH_LANES[0] - SPUR,
                              kind="station", orientation=-1.5707963267948966,
                              properties={"role": "pick-and-drop"})
        plan.edge(lane_id("s0", x), station, SPUR_SPEED, bidirectional=True,
                  restrictions={"max_speed": 0.5})

    # Parking spots and chargers above the north lanes, every 4 m; every fifth a charger.
    parking = chargers = 0
    for index, x in enumerate(range(2, int(LANE_LENGTH), 4)):
        if index % 5 == 4:
            chargers += 1
            spot = plan.vertex("charger-%02d" % chargers, x, NORTH_LANES[1] + SPUR,
                               kind="charger", orientation=1.5707963267948966,
                               properties={"power_kw": "3.0"})
        else:
            parking += 1
            spot = plan.vertex("parking-%02d" % parking, x, NORTH_LANES[1] + SPUR,
                               kind="parking", orientation=1.5707963267948966)
        plan.edge(lane_id("n1", x), spot, SPUR_SPEED, bidirectional=True)
    return plan


def render(plan):
    """One entity per line, like `drover`'s own writer, so diffs stay readable."""
    def line(entry):
        return "    " + json.dumps(entry, separators=(",", ":"))
    return "\n".join([
        "{",
        '  "name": "warehouse",',
        '  "footprint_options": {"vertex_shape": "square", "vertex_radius": 0.6, '
        '"edge_half_width": 0.7},',
        '  "vertices": [',
        ",\n".join(line(v) for v in plan.vertices),
        "  ],",
        '  "edges": [',
        ",\n".join(line(e) for e in plan.edges),
        "  ]",
        "}",
        "",
    ])


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description="Generate the bundled warehouse topology.")
    parser.add_argument("--output", default=os.path.join(here, "warehouse.json"),
                        help="where to write (default: warehouse.json next to this script)")
    arguments = parser.parse_args()
    with open(arguments.output, "w", encoding="utf-8") as out:
        out.write(render(build()))


if __name__ == "__main__":
    main()
