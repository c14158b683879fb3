#!/usr/bin/env python3
"""Tables and figures of the reproduction report (scripts/repro.sh).

    report.py jobs CLOUDS_DIR RESULTS_DIR > jobs.json
        the evaluation jobs for `repro_native eval`, from the outputs present
    report.py render CLOUDS_DIR RESULTS_DIR REPRODUCTION.md FIG_DIR
        REPRODUCTION.md and its figures (PNG with matplotlib, else SVG)

Tables need only the standard library; figures use matplotlib when it
imports (the .venv of scripts/setup-peers.sh) and fall back to plain SVG.
"""
import json
import math
import os
import re
import statistics
import sys

SIM = ["A", "B", "C", "D", "E"]
REAL = ["OS0-128", "OS1-64"]

# Outputs evaluated against the ground truth: key -> (label, kind, file pattern, family)
# family: ours | planar | mesh
EVALUATED = [
    ("gpp1", "GPP 1 (polyscene `gpp1`, concave)", "polygons", "det_{c}_gpp1.json", "ours"),
    ("gpp2", "GPP 2 (polyscene `gpp2`, concave)", "polygons", "det_{c}_gpp2.json", "ours"),
    ("gpp2-convex", "GPP 2, convex outlines", "polygons", "det_{c}_gpp2-convex.json", "ours"),
    ("pcljs", "pcl.js RANSAC x15 (convex hull of inliers)", "planes", "pcljs_{c}.json", "planar"),
    ("o3d_ransac", "Open3D segment_plane x15 + DBSCAN (hulls)", "planes", "o3d_ransac_{c}.json", "planar"),
    ("o3d_patches", "Open3D detect_planar_patches (boxes)", "polygons", "o3d_patches_{c}.json", "planar"),
    ("bpa", "Open3D ball pivoting (mesh)", "mesh", "bpa_{c}.mesh", "mesh"),
    ("poisson", "Open3D Poisson, depth 10 (mesh)", "mesh", "poisson_{c}.mesh", "mesh"),
    ("poisson_trim", "Open3D Poisson, trimmed (mesh)", "mesh", "poisson_{c}_trim.mesh", "mesh"),
    ("pcl_gp3", "PCL greedy projection triangulation (mesh)", "mesh", "pcl_gp3_{c}.mesh", "mesh"),
]
PAPER_HAUSDORFF = {"gpp1": "0.99", "gpp2-convex": "0.83", "pcl_gp3": "0.14", "poisson": "1.43", "bpa": "reference"}
PAPER_TIME = {"gpp1": "25.5", "gpp2-convex": "35.5", "pcl_gp3": "151.8", "poisson": "58.3", "bpa": "585.9"}


def load(path, default=None):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return default


def jobs(clouds, res):
    out = []
    for c in SIM:
        for key, _, kind, pat, _ in EVALUATED:
            p = os.path.join(res, pat.format(c=c))
            if os.path.exists(p):
                out.append({"id": f"{key}|{c}", "cloud": c, "kind": kind, "path": p})
        for key in ("gpp2", "gpp2-convex", "gpp1"):
            p = os.path.join(res, f"det_{c}_{key}.json")
            if os.path.exists(p):
                out.append({"id": f"{key}|noground|{c}", "cloud": c, "kind": "polygons", "path": p, "dropGround": True})
    # Cross-check of the mesh evaluator against polyscene::eval on one location.
    p = os.path.join(res, "det_A_gpp2.json")
    if os.path.exists(p):
        out.append({"id": "gpp2|as-mesh|A", "cloud": "A", "kind": "polygons-as-mesh", "path": p})
    json.dump(out, sys.stdout, indent=1)


# --- formatting ---------------------------------------------------------------


def fs(ms):
    """Milliseconds as seconds."""
    if ms is None:
        return "–"
    s = ms / 1000
    if s < 1:
        return f"{s:.3f}"
    if s < 10:
        return f"{s:.2f}"
    return f"{s:.1f}"


def fm(x, d=3):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    return f"{x:.{d}f}"


def fmed(x):
    """A median distance: often far below a millimetre (points on the surface)."""
    if x is None:
        return "–"
    return "< 0.0001" if x < 0.0001 else f"{x:.4f}"


def pct(x):
    return "–" if x is None else f"{100 * x:.1f} %"


def mean(xs):
    xs = [x for x in xs if x is not None]
    return sum(xs) / len(xs) if xs else None


def table(header, rows, align=None):
    align = align or ["l"] + ["r"] * (len(header) - 1)
    sep = ["---:" if a == "r" else "---" for a in align]
    lines = ["| " + " | ".join(header) + " |", "| " + " | ".join(sep) + " |"]
    for r in rows:
        lines.append("| " + " | ".join(str(x) for x in r) + " |")
    return "\n".join(lines)


# --- figures --------------------------------------------------------------------

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    HAVE_MPL = True
except Exception:  # noqa: BLE001
    HAVE_MPL = False

COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"]


def svg_panels(path, title, panels, width=900, height_per=260):
    """A minimal SVG line chart (fallback without matplotlib): panels is a list
    of (ylabel, xlabel, [(name, xs, ys)], logy)."""
    h = 40 + height_per * len(panels)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{h}" font-family="sans-serif" font-size="12">',
           '<rect width="100%" height="100%" fill="white"/>',
           f'<text x="{width / 2}" y="22" text-anchor="middle" font-size="15">{title}</text>']
    for k, (ylabel, xlabel, series, logy) in enumerate(panels):
        x0, y0, w, hh = 100, 40 + k * height_per + 10, width - 260, height_per - 60
        xs_all = [x for _, xs, _ in series for x in xs]
        ys_all = [y for _, _, ys in series for y in ys if y is not None and (not logy or y > 0)]
        if not xs_all or not ys_all:
            continue
        xmin, xmax = min(xs_all), max(xs_all) or 1
        f = (lambda v: math.log10(v)) if logy else (lambda v: v)
        ymin, ymax = f(min(ys_all)), f(max(ys_all))
        if not logy:
            ymin = min(0, ymin)
        if ymax == ymin:
            ymax = ymin + 1
        X = lambda v: x0 + (v - xmin) / ((xmax - xmin) or 1) * w  # noqa: E731
        Y = lambda v: y0 + hh - (f(v) - ymin) / (ymax - ymin) * hh  # noqa: E731
        out.append(f'<rect x="{x0}" y="{y0}" width="{w}" height="{hh}" fill="none" stroke="#888"/>')
        out.append(f'<text x="15" y="{y0 + hh / 2}" transform="rotate(-90 15 {y0 + hh / 2})" text-anchor="middle">{ylabel}</text>')
        out.append(f'<text x="{x0 + w / 2}" y="{y0 + hh + 30}" text-anchor="middle">{xlabel}</text>')
        for t in range(5):
            yv = ymin + (ymax - ymin) * t / 4
            lab = 10 ** yv if logy else yv
            yy = y0 + hh - hh * t / 4
            txt = f"{lab:,.0f}" if abs(lab) >= 100 else f"{lab:.3g}"
            out.append(f'<text x="{x0 - 5}" y="{yy + 4}" text-anchor="end">{txt}</text>')
        for t in range(5):
            xv = xmin + (xmax - xmin) * t / 4
            out.append(f'<text x="{X(xv)}" y="{y0 + hh + 15}" text-anchor="middle">{xv:.0f}</text>')
        for i, (name, xs, ys) in enumerate(series):
            pts = " ".join(f"{X(x):.1f},{Y(y):.1f}" for x, y in zip(xs, ys) if y is not None and (not logy or y > 0))
            col = COLORS[i % len(COLORS)]
            out.append(f'<polyline fill="none" stroke="{col}" stroke-width="1.5" points="{pts}"/>')
            out.append(f'<text x="{x0 + w + 10}" y="{y0 + 15 + 16 * i}" fill="{col}">{name}</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out))


def fig9(res, figdir):
    steps = {c: (load(os.path.join(res, f"det_{c}_gpp2.json")) or {}).get("steps") for c in SIM}
    steps = {c: s for c, s in steps.items() if s}
    if not steps:
        return None
    if HAVE_MPL:
        fig, ax = plt.subplots(1, 2, figsize=(12, 4.6))
        for i, (c, s) in enumerate(steps.items()):
            r = list(range(1, len(s) + 1))
            col = COLORS[i]
            left = [x["pointsLeft"] / 1e6 for x in s]
            ax[0].plot(r, left, color=col, lw=1.5, label=f"location {c}")
            acc = [k for k, x in enumerate(s) if x["accepted"]]
            ax[0].plot([r[k] for k in acc], [left[k] for k in acc], "o", color=col, ms=3)
            t = [x["timeMs"] for x in s]
            ax[1].plot(r, t, color=col, lw=1.2, label=f"location {c}")
            ax[1].plot([r[k] for k in acc], [t[k] for k in acc], "o", color=col, ms=3)
        ax[0].set_xlabel("cascade round")
        ax[0].set_ylabel("points left before the round (millions)")
        ax[0].set_title("points still in play (dots: a primitive was accepted)")
        ax[0].set_ylim(bottom=0)
        ax[1].set_yscale("log")
        ax[1].set_xlabel("cascade round")
        ax[1].set_ylabel("time of the round (ms, log scale)")
        ax[1].set_title("time per round")
        for a in ax:
            a.grid(alpha=0.3)
            a.legend(fontsize=8)
        fig.suptitle("Fig. 9 (reproduced): gpp2 detection cascade on the five 1.2 M-point locations (native)")
        fig.tight_layout()
        p = os.path.join(figdir, "fig9_cascade.png")
        fig.savefig(p, dpi=110)
        plt.close(fig)
        return p
    p = os.path.join(figdir, "fig9_cascade.svg")
    svg_panels(p, "Fig. 9: gpp2 cascade (native)", [
        ("points left (M)", "cascade round",
         [(f"location {c}", list(range(1, len(s) + 1)), [x["pointsLeft"] / 1e6 for x in s]) for c, s in steps.items()], False),
        ("ms per round (log)", "cascade round",
         [(f"location {c}", list(range(1, len(s) + 1)), [x["timeMs"] for x in s]) for c, s in steps.items()], True),
    ])
    return p


def fig14(exp, noexp, figdir):
    if not exp or not noexp:
        return None
    keys = [("polygonCount", "polygons in the scenario"), ("sentToDetection", "points sent to detection"),
            ("totalArea", "total polygon area (m²)")]
    if HAVE_MPL:
        fig, ax = plt.subplots(1, 3, figsize=(15, 4.4))
        for a, (k, lab) in zip(ax, keys):
            a.plot([r["scan"] for r in exp], [r[k] for r in exp], color=COLORS[0], lw=1.6, label="with expansion")
            a.plot([r["scan"] for r in noexp], [r[k] for r in noexp], color=COLORS[3], lw=1.6, label="without expansion")
            a.set_xlabel("scan")
            a.set_title(lab)
            a.grid(alpha=0.3)
            a.legend(fontsize=9)
            a.set_ylim(bottom=0)
        fig.suptitle("Fig. 14 (reproduced): incremental scenario over the simulated street drive (gpp2, native)")
        fig.tight_layout()
        p = os.path.join(figdir, "fig14_expansion.png")
        fig.savefig(p, dpi=110)
        plt.close(fig)
        return p
    p = os.path.join(figdir, "fig14_expansion.svg")
    svg_panels(p, "Fig. 14: with and without expansion", [
        (lab, "scan", [("with expansion", [r["scan"] for r in exp], [r[k] for r in exp]),
                       ("without expansion", [r["scan"] for r in noexp], [r[k] for r in noexp])], False)
        for k, lab in keys])
    return p


def fig_accuracy(points, figdir):
    """Mean one-sided Hausdorff vs completeness, one point per method (mean over locations)."""
    if not HAVE_MPL or not points:
        return None
    fig, ax = plt.subplots(figsize=(8.5, 5.2))
    marker = {"ours": "o", "planar": "s", "mesh": "^"}
    for i, (label, fam, h, c) in enumerate(points):
        if h is None or c is None:
            continue
        ax.scatter([c * 100], [h], marker=marker[fam], s=60, color=COLORS[i % len(COLORS)], label=label, zorder=3)
    ax.set_yscale("log")
    ax.set_xlabel("completeness (% of the observed ground truth within 0.1 m)")
    ax.set_ylabel("mean one-sided Hausdorff distance to the ground truth (m, log)")
    ax.set_title("Accuracy vs completeness, mean over locations A–E (o ours, □ planar peers, △ meshes)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7.5, loc="best")
    fig.tight_layout()
    p = os.path.join(figdir, "accuracy_completeness.png")
    fig.savefig(p, dpi=110)
    plt.close(fig)
    return p


# --- render -----------------------------------------------------------------------


def read_env(res):
    env = {}
    try:
        for line in open(os.path.join(res, "env.txt")):
            k, _, v = line.rstrip("\n").partition("=")
            env[k] = v
    except OSError:
        pass
    return env


def read_jsonl(path):
    try:
        return [json.loads(x) for x in open(path) if x.strip()]
    except (OSError, ValueError):
        return None


def parse_eval_text(path):
    try:
        t = open(path).read()
    except OSError:
        return None
    g = lambda pat: (lambda m: float(m.group(1)) if m else None)(re.search(pat, t))  # noqa: E731
    return {"mean": g(r"\n\s+mean\s+([\d.]+) m"), "median": g(r"\n\s+median\s+([\d.]+) m"),
            "max": g(r"\n\s+max\s+([\d.]+) m"), "completeness": g(r"\n\s+completeness\s+([\d.]+)\n"),
            "precision": g(r"precision\s+([\d.]+)"), "recall": g(r"recall\s+([\d.]+)"),
            "pairs": g(r"\n\s+pairs\s+(\d+)"), "polygons": g(r"\n\s+polygons\s+(\d+)"),
            "vertices": g(r"\n\s+vertices\s+(\d+)"), "polygon_bytes": g(r"polygon bytes\s+(\d+)"),
            "input_points": g(r"input points\s+(\d+)"), "input_bytes": g(r"input bytes\s+(\d+)")}


def render(clouds, res, md_path, figdir):
    os.makedirs(figdir, exist_ok=True)
    env = read_env(res)
    manifest = load(os.path.join(clouds, "manifest.json"), {"clouds": []})
    cinfo = {c["name"]: c for c in manifest["clouds"]}
    native = load(os.path.join(res, "native_times.json"), [])
    nt = {(e["cloud"], e["variant"]): e for e in native}
    node = load(os.path.join(res, "node_times.json"), {}) or {}
    nodeby = {e["cloud"]: e for e in node.get("results", [])}
    peers = load(os.path.join(res, "peer_times.json"), {}) or {}
    peerby = {(e["cloud"], e["method"]): e for e in peers.get("results", [])}
    ev = {e["id"]: e for e in (load(os.path.join(res, "eval.json"), []) or [])}
    status = open(os.path.join(res, "status.txt")).read().strip() if os.path.exists(os.path.join(res, "status.txt")) else ""
    clouds_present = [c for c in SIM + REAL if c in cinfo]
    sims = [c for c in SIM if c in cinfo]
    reals = [c for c in REAL if c in cinfo]
    rep_sim, rep_real = env.get("rep_sim", "3"), env.get("rep_real", "5")
    pcl_rep_real = env.get("pcljs_rep_real", "3")
    wasm_ok = node.get("wasm", {}).get("available")
    pcl_ok = node.get("pcljs", {}).get("available")
    o3d_v = peers.get("open3d")
    pcl_tools_v = peers.get("pcl_tools")
    voxel = peers.get("voxel", 0.1)

    L = []
    A = L.append
    summary = []

    def prov(runs):
        return (f"<sub>Machine: {env.get('cpu', '?')}, {env.get('cores', '?')} cores; {env.get('rustc', '?')}, "
                f"polyscene {env.get('rev', '?')}, Node {env.get('node', '?')}, pcl.js {node.get('pcljs', {}).get('version') or '–'}, "
                f"Open3D {o3d_v or '–'}, pcl-tools {pcl_tools_v or '–'}; made by `make repro`; {runs}.</sub>")

    A("# Reproduction report: Oliveira et al. 2016 with polyscene")
    A("")
    A("Generated by `make repro` (`scripts/repro.sh`; raw results in `target/repro/results/`). "
      "Do not edit by hand: rerun the command.")
    A("")
    A("**Machine and versions.** " + "; ".join([
        f"CPU {env.get('cpu', '?')}, {env.get('cores', '?')} cores, {env.get('mem', '?')} (shared, noisy machine)",
        f"{env.get('os', '')}",
        f"{env.get('rustc', 'rustc ?')}",
        f"polyscene git rev {env.get('rev', '?')}",
        f"Node {env.get('node', node.get('node', '?'))}",
        f"polyscene wasm (pkg/node) {node.get('wasm', {}).get('version') or 'not available'}",
        f"pcl.js {node.get('pcljs', {}).get('version') or 'not installed'}",
        f"Open3D {o3d_v or 'not installed'}",
        f"PCL (Debian pcl-tools) {pcl_tools_v or 'not installed'}",
    ]) + ".")
    A("")
    A(f"**Command.** `make repro` (= `scripts/setup.sh rust npm && scripts/repro.sh`), "
      f"{int(env.get('seconds', '0')) // 60} min {int(env.get('seconds', '0')) % 60} s wall time on {env.get('date', '?')}. "
      f"Fast methods: median of {rep_sim} runs per simulated location and {rep_real} per real scan, "
      "runs of the methods interleaved (round-robin) so that load spikes of the shared machine hit every method alike; "
      f"slow peers (meshing, Open3D RANSAC + DBSCAN) and pcl.js on the locations: 1 run; pcl.js on the real scans: {pcl_rep_real} runs; "
      "detect_planar_patches on the real scans: 3 runs.")
    A("")
    summary_at = len(L)
    if status:
        A("**Skipped or failed in this run:**")
        A("")
        for line in status.splitlines():
            A(f"- {line}")
        A("")
    skipped = [e for e in peers.get("results", []) if e.get("skipped")]
    if skipped:
        reasons = sorted({f"{e['label']}: {e['skipped']}" for e in skipped})
        A("**Peers skipped:** " + "; ".join(reasons) + ".")
        A("")
    if not node.get("pcljs", {}).get("available", False) and node:
        A(f"**pcl.js skipped:** {node.get('pcljs', {}).get('why', 'not run')}.")
        A("")
    if not wasm_ok and node:
        A(f"**wasm rows skipped:** {node.get('wasm', {}).get('why', 'not run')}.")
        A("")

    # --- data ---
    A("## Data")
    A("")
    rows = []
    for c in clouds_present:
        i = cinfo[c]
        rows.append([f"**{c}**", f"{i['points']:,}", i["description"], f"({', '.join(f'{v:.1f}' for v in i['viewpoint'])})"])
    A(table(["cloud", "points", "what", "viewpoint (m)"], rows, ["l", "r", "l", "l"]))
    A("")
    A("The locations follow the paper: about ten consecutive HDL-64E scans accumulated in the world frame "
      "(~1.2 M points; the paper used ~1.3 M points of the MIT DARPA Urban Challenge data, which cannot be "
      "downloaded here). They come from polyscene's built-in simulator (street layout, seed 1), so every point "
      "carries the id of the ground-truth polygon it lies on; the viewpoint given to detection is the mean sensor "
      "position of the ten scans. The two real Ouster scans (from `/work/shared/data`) have no ground truth: "
      "they enter the timing tables only. Every method reads the same `.bin` files.")
    A("")

    # --- Table 3 ---
    A("## Table 3: processing time per location")
    A("")
    A("Seconds, median over runs (see above). Time of the computation only: cloud in memory to output in memory "
      "(file I/O excluded); preprocessing a method needs (normal estimation, downsampling) included.")
    A("")
    hdr = ["method"] + [f"{c}" for c in clouds_present] + ["paper (s, 1.3 M pts, i7-860)"]
    rows = []

    def row_native(variant, label, paper=""):
        cells = [fs(nt[(c, variant)]["medianMs"]) if (c, variant) in nt else "–" for c in clouds_present]
        rows.append([label] + cells + [paper])

    row_native("gpp1", "GPP 1, native (`gpp1`, concave outlines)", PAPER_TIME["gpp1"] + " (GPP 1)")
    row_native("gpp2", "GPP 2, native (`gpp2`, concave outlines)", "")
    row_native("gpp2-convex", "GPP 2, native, convex outlines (the paper's GPP 2)", PAPER_TIME["gpp2-convex"] + " (GPP 2)")
    if wasm_ok:
        for p in ("gpp1", "gpp2"):
            rows.append([f"GPP {p[-1]}, wasm in Node (`pkg/node`, `detect`)"] +
                        [fs(nodeby.get(c, {}).get(f"wasm_{p}", {}).get("medianMs")) for c in clouds_present] + [""])
    if pcl_ok:
        rows.append(["pcl.js RANSAC loop, 15 planes: `segment()` calls only"] +
                    [fs(nodeby.get(c, {}).get("pcljs", {}).get("medianSegMs")) for c in clouds_present] + [""])
        rows.append(["pcl.js RANSAC loop, 15 planes: whole loop (incl. removing inliers)"] +
                    [fs(nodeby.get(c, {}).get("pcljs", {}).get("medianLoopMs")) for c in clouds_present] + [""])
    for key, label, paper in [("o3d_ransac", "Open3D segment_plane x15 + DBSCAN", ""),
                              ("o3d_patches", "Open3D detect_planar_patches (with normals)", ""),
                              ("bpa", "Open3D ball pivoting (with normals)", PAPER_TIME["bpa"]),
                              ("poisson", "Open3D Poisson depth 10 (with normals)", PAPER_TIME["poisson"]),
                              ("pcl_gp3", "PCL greedy projection triangulation (with normals)", PAPER_TIME["pcl_gp3"])]:
        es = [peerby.get((c, key)) for c in clouds_present]
        if not any(e and not e.get("skipped") for e in es):
            continue
        star = any(e and e.get("downsampled") for e in es)
        cells = []
        for e in es:
            if not e or e.get("skipped"):
                cells.append("–")
            else:
                cells.append(fs(e["medianMs"]) + ("*" if e.get("downsampled") else ""))
        rows.append([label + (" *" if star else "")] + cells + [paper])
    rows.append(["input points"] + [f"{cinfo[c]['points'] / 1e6:.2f} M" for c in clouds_present] + ["1.3 M"])
    A(table(hdr, rows))
    A(prov(f"median of {rep_sim} (locations) / {rep_real} (real scans) interleaved runs for polyscene native and wasm; "
           f"pcl.js 1 run per location, {pcl_rep_real} per real scan; Open3D/PCL 1 run (planar patches: 3 on the real scans)"))
    A("")
    small = [peerby[(c, "bpa")]["inputPoints"] for c in sims if peerby.get((c, "bpa"), {}).get("inputPoints")]
    small_txt = ", ".join(f"{n:,}" for n in small) if small else "?"
    A(f"\\* run on the location downsampled to one point per {voxel:g} m voxel (the centroid of each occupied voxel, "
      f"{small_txt} points "
      "for A–E) so that the run stays bounded (ball pivoting, Poisson and DBSCAN on 1.2 M points take minutes each on "
      "2 cores; one segment_plane + DBSCAN round on the full location A takes ~90 s). "
      "These rows are therefore *not* a like-for-like time comparison with the full-resolution rows; the real scans "
      "are used whole by every method. Open3D and PCL may use both cores (OpenMP); polyscene and pcl.js use one.")
    A("")
    # polygon counts
    rows = []
    for variant, label in [("gpp1", "GPP 1 native"), ("gpp2", "GPP 2 native"), ("gpp2-convex", "GPP 2 convex native")]:
        rows.append([label] + [str(nt[(c, variant)]["polygons"]) if (c, variant) in nt else "–" for c in clouds_present])
    if wasm_ok:
        for p in ("gpp1", "gpp2"):
            rows.append([f"GPP {p[-1]} wasm"] + [str(nodeby.get(c, {}).get(f"wasm_{p}", {}).get("polygons", "–")) for c in clouds_present])
    if pcl_ok:
        rows.append(["pcl.js planes"] + [str(nodeby.get(c, {}).get("pcljs", {}).get("planes", "–")) for c in clouds_present])
    for key, label in [("o3d_ransac", "Open3D RANSAC+DBSCAN polygons"), ("o3d_patches", "Open3D planar patches"),
                       ("bpa", "BPA triangles"), ("poisson", "Poisson triangles"), ("pcl_gp3", "GP3 triangles")]:
        es = [peerby.get((c, key)) for c in clouds_present]
        if any(e and not e.get("skipped") for e in es):
            rows.append([label] + [str(e.get("polygons", e.get("triangles", "–"))) if e and not e.get("skipped") else "–" for e in es])
    A("Output size (polygons, planes or triangles) of the same runs:")
    A("")
    A(table(["method"] + clouds_present, rows))
    A("")
    if wasm_ok:
        ratios = [nodeby[c]["wasm_gpp2"]["medianMs"] / nt[(c, "gpp2")]["medianMs"] for c in clouds_present
                  if (c, "gpp2") in nt and nodeby.get(c, {}).get("wasm_gpp2")]
        if ratios:
            A(f"wasm / native time for gpp2: median {statistics.median(ratios):.2f} (range {min(ratios):.2f}–{max(ratios):.2f}) "
              "over the clouds; the wasm time is wall time of the JS call (copying the points in, the polygons out), the "
              "native time is the detector's own clock.")
            A("")
        same = [c for c in clouds_present if (c, "gpp2") in nt and nodeby.get(c, {}).get("wasm_gpp2", {}).get("polygons") == nt[(c, "gpp2")]["polygons"]]
        A(f"Native and wasm builds give the same gpp2 polygon count on {len(same)} of {len(clouds_present)} clouds "
          "(same code, same seed; the SIMD kernels of both builds keep the scalar reference's order of operations, so they should agree exactly).")
        A("")

    # --- target 1 ---
    A("### Target: gpp2 one-shot detection at least 40x faster than pcl.js's plain RANSAC loop (same Node process)")
    A("")
    t1 = []
    if wasm_ok and pcl_ok:
        rows = []
        seed_rows = []
        for c in clouds_present:
            e = nodeby.get(c, {})
            w = e.get("wasm_gpp2", {}).get("medianMs")
            p = e.get("pcljs", {})
            if w is None or not p:
                continue
            r1 = p["medianSegMs"] / w
            r2 = p["medianLoopMs"] / w
            if c in reals:
                t1.append(r1)
            rows.append([c + (" (real)" if c in reals else ""), f"{cinfo[c]['points']:,}", fs(w), fs(p["medianSegMs"]), fs(p["medianLoopMs"]),
                         f"**{r1:.1f}x**", f"{r2:.1f}x", "yes" if r1 >= 40 else "no"])
            sd = e.get("wasm_gpp2_seeds")
            if sd:
                ts = sd["timesMs"]
                seed_rows.append([c, f"1-{sd['seeds']}", fs(sd["medianMs"]), f"{fs(min(ts))}-{fs(max(ts))}",
                                  f"{min(sd['polygons'])}-{max(sd['polygons'])}", fs(w),
                                  f"{p['medianSegMs'] / sd['medianMs']:.1f}x"])
        A(table(["cloud", "points", "gpp2 wasm (s)", "pcl.js segment() (s)", "pcl.js loop (s)",
                 "speed-up vs segment()", "vs whole loop", "≥ 40x?"], rows))
        A(prov(f"one Node process, runs interleaved; gpp2 median of {rep_sim}/{rep_real} runs, pcl.js median of 1/{pcl_rep_real} runs"))
        A("")
        if seed_rows:
            A("The rows above use the default RANSAC seed, as a user gets it. How long the cascade runs (how many "
              "rounds before ten rejections in a row end it) depends on the seed; gpp2 once per seed on the real scans:")
            A("")
            A(table(["cloud", "seeds", "gpp2 wasm, median over the seeds (s)", "range (s)", "polygons",
                     "default seed (s)", "speed-up vs segment() at the median"], seed_rows))
            A(prov("one Node process, after the runs above; one run per seed"))
            A("")
            A("pcl.js is not run again here: the last column divides its median from the runs above by these later "
              "runs, so it is only as good as the machine's load was steady in between. The default-seed rows above, "
              "run in the same rounds, are the like-for-like comparison.")
            A("")
        A("pcl.js: `SACSegmentation` (plane, `SAC_RANSAC`, 0.10 m — the gpp2 inlier distance —, 1000 iterations, "
          "coefficients optimised) on the remaining points, 15 times, each plane's inliers removed. "
          "pcl.js has no `ExtractIndices`, so the loop rebuilds the remaining cloud from JS; the conservative ratio "
          "uses the time spent inside `segment()` only. Both libraries run in the same Node process, interleaved.")
        A("")
        if t1:
            ok = all(r >= 40 for r in t1)
            v = (f"**{'MET' if ok else 'NOT MET'}**: speed-up {', '.join(f'{r:.1f}x' for r in t1)} on the real scans "
                 f"({', '.join(reals)}) (target ≥ 40x)")
            A(f"**Verdict:** {v}.")
            summary.append(("gpp2 one-shot detection ≥ 40x faster than pcl.js's RANSAC loop (15 planes), same real scan, same Node process", v))
            A("")
    else:
        A("Not measured in this run: " + ("pcl.js is missing. " if not pcl_ok else "") + ("the wasm build is missing." if not wasm_ok else ""))
        A("")

    # --- Table 4 ---
    A("## Table 4: accuracy against the ground truth (simulated locations A–E)")
    A("")
    A("One-sided Hausdorff distance from each method's output to the ground-truth polygons "
      "(definitions: `src/eval/mod.rs`): our polygons and the planar peers' polygons are scored by "
      "`polyscene::eval::evaluate` (dense 0.1 m grid samples over each polygon, area-weighted mean and median; max over "
      "samples and outlines); meshes have up to hundreds of thousands of triangles, which `evaluate` (whose duplicate "
      "check is quadratic) is not made for, so `examples/repro_native.rs` scores them with the same definitions: "
      "every triangle sampled at the same density (at least one sample, weight = its area share), exact distances to "
      "the nearest ground-truth polygon, max over samples and vertices; completeness over the same observed cells.")
    A("")
    A("Planar peers are turned into polygons as follows: RANSAC planes (pcl.js, Open3D segment_plane) become the "
      "2D convex hull of their inliers projected on the plane (each DBSCAN cluster its own polygon for Open3D); "
      "planar patches are Open3D's oriented boxes flattened to their two long axes. "
      "**Completeness**: share of the observed ground-truth area (0.25 m cells of labelled points) within 0.1 m of the "
      "output. **Precision / recall** (plane level, not in the paper): a polygon is a true positive when most of it lies "
      "within 0.15 m of one ground-truth surface with a matching normal (10°); a surface is found when half of its "
      "observed area is matched. For meshes these do not apply: n/a.")
    A("")

    def agg(key, loc_list=sims):
        es = [ev.get(f"{key}|{c}") for c in loc_list]
        es = [e for e in es if e and "error" not in e]
        if not es:
            return None
        d = lambda e: e.get("detection") or {}  # noqa: E731
        return {
            "n": len(es),
            "mean": mean([e["accuracy"]["mean"] for e in es]),
            "median": mean([e["accuracy"]["median"] for e in es]),
            "max": max((e["accuracy"]["max"] for e in es if e["accuracy"]["max"] is not None), default=None),
            "completeness": mean([e["completeness"]["completeness"] for e in es]),
            "points": mean([e.get("pointCoverage") for e in es]),
            "precision": mean([d(e).get("precision") for e in es]) if es[0].get("detection") else None,
            "recall": mean([d(e).get("recall") for e in es]) if es[0].get("detection") else None,
            "dups": sum(e.get("duplicates", 0) or 0 for e in es) if es[0].get("detection") else None,
            "polys": mean([d(e).get("predictions") for e in es]) if es[0].get("detection") else None,
        }

    rows = []
    scatter = []
    aggs = {}
    for key, label, kind, _, fam in EVALUATED:
        a = agg(key)
        if not a:
            continue
        aggs[key] = a
        is_mesh = fam == "mesh"
        rows.append([label, fm(a["mean"]), fmed(a["median"]), fm(a["max"], 2), pct(a["completeness"]),
                     "n/a" if is_mesh else pct(a["points"]),
                     "n/a" if is_mesh else pct(a["precision"]), "n/a" if is_mesh else pct(a["recall"]),
                     "n/a" if is_mesh else f"{a['polys']:.1f}", PAPER_HAUSDORFF.get(key, ""), f"{a['n']}"])
        scatter.append((label, fam, a["mean"], a["completeness"]))
    A(table(["method", "mean (m)", "median (m)", "max (m)", "completeness", "labelled points within 0.1 m",
             "precision", "recall", "polygons", "paper mean (m)", "locations"], rows))
    A(prov("polyscene::eval / repro_native eval, deterministic (one evaluation per output)"))
    A("")
    A("Mean, median, completeness, precision and recall: averages over the locations; max: the largest over them. "
      "The paper's distances are to a ball-pivoting mesh of the real data (its own reference, so no BPA row there), "
      "ours to the exact ground truth of the simulator; the paper's 0.83 m is its GPP 2 with convex outlines and the "
      "ground. Meshes also cover clutter (trees, poles) that has no ground-truth polygon, which raises their distances.")
    A("")
    # per-location table
    rows = []
    for key, label, kind, _, fam in EVALUATED:
        if key not in aggs:
            continue
        cells = []
        for c in sims:
            e = ev.get(f"{key}|{c}")
            cells.append(f"{fm(e['accuracy']['mean'])} / {pct(e['completeness']['completeness'])}" if e and "error" not in e else "–")
        rows.append([label] + cells)
    A("Per location, mean one-sided Hausdorff (m) / completeness:")
    A("")
    A(table(["method"] + sims, rows))
    A("")
    # completeness by kind for gpp2 vs best planar peer
    kinds_rows = []
    for key in ("gpp2", "gpp2-convex", "pcljs", "o3d_ransac", "o3d_patches", "bpa"):
        es = [ev.get(f"{key}|{c}") for c in sims]
        es = [e for e in es if e and e.get("byKind")]
        if not es:
            continue
        tot = {}
        for e in es:
            for k, v in e["byKind"].items():
                o, cv = tot.get(k, (0, 0))
                tot[k] = (o + v["observed"], cv + v["covered"])
        kinds_rows.append((key, tot))
    if kinds_rows:
        allk = sorted({k for _, t in kinds_rows for k in t}, key=lambda k: -kinds_rows[0][1].get(k, (0, 0))[0])
        label_of = {k: l for k, l, *_ in EVALUATED}
        rows = [[label_of[key]] + [pct(t[k][1] / t[k][0]) if k in t and t[k][0] > 0 else "–" for k in allk] for key, t in kinds_rows]
        obs = kinds_rows[0][1]
        rows.append(["*observed area, A–E (m²)*"] + [f"{obs[k][0]:,.0f}" if k in obs else "–" for k in allk])
        A("Where the completeness comes from: covered share of the observed area per ground-truth kind, locations A–E together:")
        A("")
        A(table(["method"] + allk, rows))
        A("")
    xcheck = ev.get("gpp2|as-mesh|A")
    if xcheck and ev.get("gpp2|A"):
        e = ev["gpp2|A"]
        A(f"Cross-check of the mesh scorer: gpp2's polygons on location A triangulated and scored as a mesh give mean "
          f"{fm(xcheck['accuracy']['mean'], 4)} m, max {fm(xcheck['accuracy']['max'], 3)} m, completeness "
          f"{pct(xcheck['completeness']['completeness'])}; `polyscene::eval` on the polygons gives "
          f"{fm(e['accuracy']['mean'], 4)} m, {fm(e['accuracy']['max'], 3)} m, {pct(e['completeness']['completeness'])} "
          "(the samples differ: a grid per polygon vs a low-discrepancy set per triangle).")
        A("")
    p = fig_accuracy(scatter, figdir)
    if p:
        A(f"![accuracy vs completeness]({os.path.relpath(p, os.path.dirname(md_path) or '.')})")
        A("")

    # --- target 2 ---
    A("### Target: gpp2 more accurate than every peer's planar output, and at least as complete")
    A("")
    g = aggs.get("gpp2")
    planar = [(k, l) for k, l, _, _, fam in EVALUATED if fam == "planar" and k in aggs]
    if g and planar:
        rows = []
        ok_acc = ok_comp = True
        for k, l in planar:
            a = aggs[k]
            acc = g["mean"] < a["mean"]
            comp = g["completeness"] >= a["completeness"]
            wins_a = sum(1 for c in sims if ev.get(f"gpp2|{c}") and ev.get(f"{k}|{c}") and "error" not in ev[f"{k}|{c}"] and ev[f"gpp2|{c}"]["accuracy"]["mean"] < ev[f"{k}|{c}"]["accuracy"]["mean"])
            wins_c = sum(1 for c in sims if ev.get(f"gpp2|{c}") and ev.get(f"{k}|{c}") and "error" not in ev[f"{k}|{c}"] and ev[f"gpp2|{c}"]["completeness"]["completeness"] >= ev[f"{k}|{c}"]["completeness"]["completeness"])
            ok_acc &= acc
            ok_comp &= comp
            rows.append([l, f"{fm(a['mean'])} vs **{fm(g['mean'])}**", "yes" if acc else "no", f"{wins_a}/{a['n']}",
                         f"{pct(a['completeness'])} vs **{pct(g['completeness'])}**", "yes" if comp else "no", f"{wins_c}/{a['n']}"])
        A(table(["peer (planar output)", "mean Hausdorff, peer vs gpp2 (m)", "gpp2 more accurate?", "per location",
                 "completeness, peer vs gpp2", "gpp2 at least as complete?", "per location"], rows))
        A(prov("averages over the five locations"))
        A("")
        worst_acc = min(aggs[k]["mean"] for k, _ in planar)
        best_comp = max(aggs[k]["completeness"] for k, _ in planar)
        v1 = (f"**{'MET' if ok_acc else 'NOT MET'}**: gpp2 {fm(g['mean'], 4)} m vs {fm(worst_acc, 3)} m for the most accurate planar peer "
              "(mean one-sided Hausdorff, average over A–E)")
        v2 = (f"**{'MET' if ok_comp else 'NOT MET'}**: gpp2 {pct(g['completeness'])} vs up to {pct(best_comp)} for the planar peers")
        A(f"**Verdict:** accuracy {v1}; completeness {v2}.")
        summary.append(("gpp2 more accurate than every peer's planar output", v1))
        summary.append(("gpp2 at least as complete as every peer's planar output", v2))
        A("")
    else:
        A("Not measured in this run (no planar peer ran).")
        A("")

    # --- Table 5 ---
    A("## Table 5: gpp2 outlines and the ground")
    A("")
    A("gpp2 on the simulated locations, convex vs concave outlines, with the ground kept or dropped (dropping = "
      "removing the primitives with `ground == true` from the output before scoring). The paper: 0.83 m (convex, "
      "ground kept) and 0.10 m (concave, ground dropped). GPP 1 for comparison.")
    A("")
    rows = []
    t5 = {}
    for variant, vlabel in [("gpp2", "concave"), ("gpp2-convex", "convex"), ("gpp1", "concave (GPP 1)")]:
        for ground, gid, paper in [("kept", f"{variant}", ""), ("dropped", f"{variant}|noground", "")]:
            a = agg(gid)
            if not a:
                continue
            t5[(variant, ground)] = a
            if variant == "gpp2-convex" and ground == "kept":
                paper = "0.83"
            if variant == "gpp2" and ground == "dropped":
                paper = "0.10"
            dropped = mean([ev.get(f"{gid}|{c}", {}).get("droppedGround") for c in sims]) if ground == "dropped" else 0
            per = " · ".join(fm(ev[f"{gid}|{c}"]["accuracy"]["mean"]) for c in sims if ev.get(f"{gid}|{c}") and "error" not in ev[f"{gid}|{c}"])
            rows.append([vlabel, ground, fm(a["mean"], 4), fmed(a["median"]), fm(a["max"], 2), pct(a["completeness"]),
                         pct(a["precision"]), pct(a["recall"]), f"{a['polys']:.1f}", f"{dropped:.1f}" if dropped else "0", per, paper])
    A(table(["outline", "ground", "mean (m)", "median (m)", "max (m)", "completeness", "precision", "recall",
             "polygons", "ground polygons dropped", "mean per location A·B·C·D·E (m)", "paper (m)"], rows))
    A(prov("outputs of the last timing run; evaluation deterministic"))
    A("")
    A("### Target: gpp2 (concave, ground kept) under 0.05 m mean one-sided Hausdorff on the simulated locations")
    A("")
    if ("gpp2", "kept") in t5:
        per = [ev[f"gpp2|{c}"]["accuracy"]["mean"] for c in sims if ev.get(f"gpp2|{c}") and "error" not in ev[f"gpp2|{c}"]]
        ok = all(x < 0.05 for x in per)
        v = (f"**{'MET' if ok else 'NOT MET'}**: mean over A–E {fm(t5[('gpp2', 'kept')]['mean'], 4)} m, worst location "
             f"{fm(max(per), 4)} m (target < 0.05 m; paper 0.83 m with the ground, 0.10 m without)")
        A(f"**Verdict:** {v}.")
        summary.append(("gpp2, concave outlines, ground kept: mean one-sided Hausdorff < 0.05 m on the simulated locations", v))
        A("")

    # --- Fig 9 ---
    A("## Fig. 9: the detection cascade")
    A("")
    p = fig9(res, figdir)
    if p:
        A(f"![Fig. 9]({os.path.relpath(p, os.path.dirname(md_path) or '.')})")
        A("")
        rows = []
        for c in sims:
            d = load(os.path.join(res, f"det_{c}_gpp2.json"))
            if not d:
                continue
            s = d["steps"]
            acc = [x for x in s if x["accepted"]]
            found = sum(int(x["accepted"]) for x in s)
            tot = sum(x["timeMs"] for x in s)
            first5 = sum(x["timeMs"] for x in s[:5])
            rows.append([c, len(s), len(acc), found, f"{tot / 1000:.2f}", f"{100 * first5 / tot:.0f} %" if tot else "–",
                         f"{100 * (1 - s[min(4, len(s) - 1)]['pointsLeft'] / s[0]['pointsLeft']):.0f} %" if s else "–",
                         f"{s[-1]['pointsLeft']:,}"])
        A(table(["location", "rounds", "rounds that accepted", "primitives accepted (before the merge pass)", "time in rounds (s)", "share of time in the first 5 rounds",
                 "points removed by the first 4 rounds", "points left at the last round"], rows))
        A(prov("cascade of the last native gpp2 run (times of that run)"))
        A("")
        A("As in the paper, RANSAC takes the largest planes first (the road, the sidewalks, long facades), so the cloud "
          "shrinks fastest in the first rounds and the later rounds are cheaper. A round judges every cluster of its "
          "plane with `minInliers` points, so one round can accept several primitives (the facades along a street, "
          "cars parked in a row). Rejected rounds (no dot) take their clusters out of play too, so the loop always "
          "progresses. From the last run of the timing table.")
        A("")

    # --- Fig 14 ---
    exp = read_jsonl(os.path.join(res, "replay_exp.jsonl"))
    noexp = read_jsonl(os.path.join(res, "replay_noexp.jsonl"))
    A("## Fig. 14: incremental scenario with and without expansion")
    A("")
    p = fig14(exp, noexp, figdir)
    if p:
        A(f"![Fig. 14]({os.path.relpath(p, os.path.dirname(md_path) or '.')})")
        A("")
        e1 = parse_eval_text(os.path.join(res, "replay_exp_eval.txt")) or {}
        e0 = parse_eval_text(os.path.join(res, "replay_noexp_eval.txt")) or {}
        rows = []
        for lab, rr, ee in [("with expansion", exp, e1), ("without expansion", noexp, e0)]:
            sent = [r["sentToDetection"] / r["points"] for r in rr]
            tms = [r["timeMs"]["total"] for r in rr]
            rows.append([lab, rr[-1]["polygonCount"], f"{statistics.median(sent) * 100:.1f} %",
                         f"{rr[-1]['totalArea']:,.0f}", f"{statistics.median(tms):.1f}", f"{max(tms):.0f}",
                         fm(ee.get("mean"), 4), fm(ee.get("max"), 2), pct(ee.get("completeness")),
                         pct(ee.get("precision")), pct(ee.get("recall")), f"{int(ee['pairs'])}" if ee.get("pairs") is not None else "–"])
        A(table(["mode", "polygons at the end", "median share of a scan sent to detection", "total area at the end (m²)",
                 "median ms per scan", "max ms per scan", "map mean Hausdorff (m)", "map max (m)", "map completeness",
                 "precision", "recall", "duplicate pairs"], rows))
        A(prov("one replay per mode; ms per scan = the scenario's own timing of each scan (median over the scans)"))
        A("")
        A(f"`polyscene simulate street --seed 1 --scans {len(exp)}` then `polyscene replay` (gpp2, native, one run each) "
          "with and without `--no-expansion`; the map after the last scan is scored by `polyscene eval` against the drive's "
          "ground truth and all its labelled points. Without expansion every scan goes to detection and its polygons are "
          "added again: the count and the area grow without bound (the area double counts), as in the paper.")
        A("")

    # --- compactness ---
    A("## Compactness: bytes of polygons vs bytes of points")
    A("")
    A("Polygons in a compact encoding (`f32` x, y, z per outline vertex plus the plane as four `f32`), points as "
      "`f32` x, y, z (12 bytes); meshes as `f32` vertices plus `u32` triangle indices (12 + 12 bytes).")
    A("")
    rows = []
    for c in sims:
        e = ev.get(f"gpp2|{c}")
        if not e or "error" in e:
            continue
        k = e["compactness"]
        mesh_cells = []
        for key in ("bpa", "pcl_gp3"):
            m = ev.get(f"{key}|{c}")
            mesh_cells.append(f"{m['compactness']['bytes'] / 1e6:.2f} MB" if m and "error" not in m else "–")
        rows.append([c, f"{k['input_points']:,}", f"{k['input_bytes'] / 1e6:.1f} MB", k["polygons"], k["vertices"],
                     f"{k['polygon_bytes'] / 1e3:.1f} kB", f"{k['input_bytes'] / k['polygon_bytes']:,.0f}x"] + mesh_cells)
    e1 = parse_eval_text(os.path.join(res, "replay_exp_eval.txt")) or {}
    if e1.get("polygon_bytes"):
        rows.append([f"drive, {len(exp) if exp else '?'} scans (map with expansion)", f"{int(e1['input_points']):,}",
                     f"{e1['input_bytes'] / 1e6:.1f} MB", int(e1["polygons"]), int(e1["vertices"]),
                     f"{e1['polygon_bytes'] / 1e3:.1f} kB", f"{e1['input_bytes'] / e1['polygon_bytes']:,.0f}x", "–", "–"])
    A(table(["cloud", "points", "point bytes", "gpp2 polygons", "vertices", "polygon bytes", "points / polygons",
             "BPA mesh bytes*", "GP3 mesh bytes*"], rows))
    A(prov("sizes are exact counts"))
    A("")
    A("\\* meshes of the downsampled locations (see Table 3).")
    A("")

    # --- summary ---
    A("## Limitations and choices")
    A("")
    for s in [
        "The locations are simulated (a deterministic ray-cast HDL-64E with noise, built into polyscene), not the paper's "
        "MIT data, which is not reachable from this machine; absolute numbers are therefore not comparable with the paper's, "
        "only the ranking and the trends. The ground truth is exact, which the paper did not have (it used a BPA mesh as reference).",
        "The real scans have no ground truth: they appear in the timing tables and the pcl.js comparison only.",
        f"Slow peers run on the {voxel:g} m voxel-downsampled locations (marked *), one run each; their time is not a like-for-like "
        "comparison with our full-resolution rows, their accuracy is hardly affected by the downsampling.",
        "Peer parameters are reasonable defaults, not tuned per cloud: RANSAC distance 0.10 m (gpp2's), 1000 iterations, "
        "DBSCAN eps 0.5 m (gpp2's cluster tolerance), BPA radii 1.5/3/6 x the mean neighbour distance, Poisson depth 10, "
        "GP3 radius 0.5 m / mu 2.5, Open3D's documented defaults for planar patches, normals from 30 neighbours within 0.5 m "
        "(PCL: 20 nearest) oriented towards the viewpoint.",
        "PCL's greedy triangulation is written by `pcl_gp3_surface` as ASCII VTK with 5 significant digits (about 1 cm at "
        "100 m from the origin), which slightly inflates its distances; its time is what the two PCL tools report for their "
        "computation (normals + triangulation, without file I/O).",
        "The machine is shared with other jobs: times are medians over interleaved runs, and ratios are taken within one "
        "process (pcl.js vs wasm) or one run; expect ±20 % between runs of `make repro`.",
    ]:
        A(f"- {s}")
    A("")
    if summary:
        block = ["## Targets at a glance", "", table(["target", "verdict (values from the tables below)"],
                                                       [[t, v] for t, v in summary], ["l", "l"]), ""]
        L[summary_at:summary_at] = block
    with open(md_path, "w") as f:
        f.write("\n".join(L))
    print(f"report: wrote {md_path}" + (" (figures: PNG)" if HAVE_MPL else " (figures: SVG, matplotlib missing)"), file=sys.stderr)


if __name__ == "__main__":
    if len(sys.argv) >= 4 and sys.argv[1] == "jobs":
        jobs(sys.argv[2], sys.argv[3])
    elif len(sys.argv) >= 6 and sys.argv[1] == "render":
        render(sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5])
    else:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
