#!/usr/bin/python3
"""Breathing motion measured from a run's exported frames, in anatomical axes.

Usage: /usr/bin/python3 scripts/frame_motion.py RUN_DIR [--model DIR] [--from SECONDS] [--json FILE]

RUN_DIR is the --out of `pneuma-cli simulate ... --vtk` (frames/*.vtp and timeseries.csv at the same output
rate). The breath analysed is the first full one after --from (default: 2 s before the end of the run's
first half): end-expiration is its lowest lung volume, end-inspiration the highest after it.

Prints, from end-expiration to end-inspiration:
- every moving rib's rotation (angle [deg] and unit axis, world frame: x lateral (left), y anterior, z cranial),
  fitted to its exported bone vertices (Horn's quaternion method), and the axis's angle from the lateral direction
  in the horizontal plane (Wilson et al. 1987, J Appl Physiol 62:1872: about 55 deg for ribs 3-7);
- the diaphragm dome's mean displacement [mm] by ring (25 mm bands of distance from the apex's vertical axis)
  and sector (anterior, lateral, posterior), craniocaudal positive up.
Needs Debian's python3-vtk9 (installed with libvtk9-dev); plain Python otherwise.
"""
import argparse
import csv
import json
import math
import os
import sys
import tempfile

try:
    import vtk
except ImportError:
    sys.exit("frame_motion: needs VTK's Python module (Debian package python3-vtk9); run it with /usr/bin/python3")


def fail(message):
    sys.exit("frame_motion: " + message)


def read_polydata(path):
    if not os.path.isfile(path):
        fail("missing frame " + path + " (was the run made with --vtk?)")
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def bone_points(path):
    """body id -> {point id: (x, y, z)} of one bones frame."""
    data = read_polydata(path)
    ids = data.GetCellData().GetArray("body_id")
    if ids is None:
        fail(path + ": no body_id cell array")
    points = {}
    for c in range(data.GetNumberOfCells()):
        cell = data.GetCell(c)
        body = points.setdefault(int(ids.GetValue(c)), {})
        for k in range(cell.GetNumberOfPoints()):
            pid = cell.GetPointId(k)
            body[pid] = data.GetPoint(pid)
    return points


def gut_points(path):
    data = read_polydata(path)
    return [data.GetPoint(i) for i in range(data.GetNumberOfPoints())]


def rotation(p, q):
    """Angle [deg] and unit axis of the rotation taking point set p to q (Horn 1987, quaternion method)."""
    n = len(p)
    cp = [sum(a[i] for a in p) / n for i in range(3)]
    cq = [sum(b[i] for b in q) / n for i in range(3)]
    s = [[0.0] * 3 for _ in range(3)]
    for a, b in zip(p, q):
        for i in range(3):
            for j in range(3):
                s[i][j] += (a[i] - cp[i]) * (b[j] - cq[j])
    (sxx, sxy, sxz), (syx, syy, syz), (szx, szy, szz) = s
    m = [[sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
         [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
         [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
         [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz]]
    shift = sum(abs(x) for row in m for x in row) + 1.0  # makes the largest eigenvalue dominant
    quat = [1.0, 0.0, 0.0, 0.0]
    for _ in range(500):  # power iteration for the dominant eigenvector
        nxt = [sum((m[i][j] + (shift if i == j else 0.0)) * quat[j] for j in range(4)) for i in range(4)]
        norm = math.sqrt(sum(x * x for x in nxt))
        quat = [x / norm for x in nxt]
    if quat[0] < 0.0:
        quat = [-x for x in quat]
    angle = 2.0 * math.acos(min(1.0, quat[0]))
    sine = math.sqrt(max(1e-30, 1.0 - quat[0] ** 2))
    return math.degrees(angle), [quat[1] / sine, quat[2] / sine, quat[3] / sine]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("run", help="output directory of pneuma-cli simulate --vtk")
    parser.add_argument("--model", help="model directory (default: the run's summary.json 'model')")
    parser.add_argument("--from", dest="start", type=float, help="analyse the first breath after this time [s]")
    parser.add_argument("--json", help="also write the figures to this file")
    args = parser.parse_args()

    try:
        summary = json.load(open(os.path.join(args.run, "summary.json")))
    except (OSError, ValueError) as e:
        fail("cannot read " + os.path.join(args.run, "summary.json") + ": " + str(e))
    model_dir = args.model or summary.get("model")
    if not model_dir:
        fail("no --model and no 'model' in summary.json")
    try:
        model = json.load(open(os.path.join(model_dir, "model.json")))
    except (OSError, ValueError) as e:
        fail("cannot read " + os.path.join(model_dir, "model.json") + ": " + str(e))

    rows = list(csv.reader(open(os.path.join(args.run, "timeseries.csv"))))
    header, data = rows[0], rows[1:]
    if "lung_volume [mL]" not in header:
        fail("timeseries.csv has no 'lung_volume [mL]' column")
    column = header.index("lung_volume [mL]")
    time = [float(r[0]) for r in data]
    volume = [float(r[column]) for r in data]
    start = args.start if args.start is not None else max(time[0], 0.5 * time[-1] - 2.0)
    window = [i for i in range(len(time)) if time[i] >= start]
    if len(window) < 3:
        fail("fewer than three frames after t = %g s" % start)
    lo = min(window, key=lambda i: volume[i])
    after = [i for i in window if i > lo]
    if not after:
        fail("no end-inspiration after the end-expiration at t = %g s; give an earlier --from" % time[lo])
    hi = max(after, key=lambda i: volume[i])
    frames = os.path.join(args.run, "frames")
    out = {"end_expiration_s": time[lo], "end_inspiration_s": time[hi], "tidal_ml": volume[hi] - volume[lo],
           "ribs": [], "dome": []}
    print("end-expiration t = %.2f s, end-inspiration t = %.2f s, %.0f mL" % (time[lo], time[hi], out["tidal_ml"]))

    # ribs: rotation of each moving rib
    names = [b["name"] for b in model["bodies"]]
    a, b = bone_points("%s/bones_%06d.vtp" % (frames, lo)), bone_points("%s/bones_%06d.vtp" % (frames, hi))
    print("\nrib            angle [deg]   axis (x lat, y ant, z cran)   from lateral [deg]")
    for body in sorted(a):
        if body >= len(names) or not names[body].startswith("rib") or model["bodies"][body].get("fixed"):
            continue
        keys = sorted(a[body])[::5]
        angle, axis = rotation([a[body][k] for k in keys], [b[body][k] for k in keys])
        if axis[0] < 0.0:
            axis = [-x for x in axis]
        from_lateral = math.degrees(math.atan2(abs(axis[1]), abs(axis[0])))
        out["ribs"].append({"name": names[body], "angle_deg": angle, "axis": axis, "from_lateral_deg": from_lateral})
        print("%-14s  %6.2f      (%+.2f %+.2f %+.2f)        %5.1f" % (names[body], angle, *axis, from_lateral))

    # dome: displacement by ring and sector
    region = [n["region"] for n in model["nodes"]]
    rest = [n["x"] for n in model["nodes"]]
    dome = [i for i, r in enumerate(region) if r == "diaphragm"]
    if dome:
        ga, gb = gut_points("%s/gut_%06d.vtp" % (frames, lo)), gut_points("%s/gut_%06d.vtp" % (frames, hi))
        apex = max(dome, key=lambda i: rest[i][2])
        bins = {}
        for i in dome:
            dx, dy = rest[i][0] - rest[apex][0], rest[i][1] - rest[apex][1]
            bearing = abs(math.degrees(math.atan2(dx, dy)))
            sector = "anterior" if bearing < 45 else ("posterior" if bearing > 135 else "lateral")
            d = [1e3 * (gb[i][k] - ga[i][k]) for k in range(3)]
            outward = d[0] if rest[i][0] >= 0 else -d[0]
            bins.setdefault((int(math.hypot(dx, dy) / 0.025), sector), []).append((outward, d[1], d[2]))
        print("\ndome band [mm]  sector     nodes  lateral out  anterior  cranial   [mm]")
        for (band, sector), v in sorted(bins.items()):
            mean = [sum(x[k] for x in v) / len(v) for k in range(3)]
            out["dome"].append({"band_mm": [25 * band, 25 * band + 25], "sector": sector, "nodes": len(v),
                                "lateral_out_mm": mean[0], "anterior_mm": mean[1], "cranial_mm": mean[2]})
            print("%3d-%-3d         %-9s  %4d   %7.2f     %7.2f   %7.2f" % (25 * band, 25 * band + 25, sector, len(v), *mean))

    if args.json:
        directory = os.path.dirname(os.path.abspath(args.json))
        with tempfile.NamedTemporaryFile("w", dir=directory, delete=False, suffix=".tmp") as f:
            json.dump(out, f, indent=2)
        os.replace(f.name, args.json)


if __name__ == "__main__":
    main()
