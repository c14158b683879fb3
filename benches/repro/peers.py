#!/usr/bin/env python3
"""Open3D and PCL (Debian pcl-tools) peers of the reproduction report.

    .venv/bin/python benches/repro/peers.py CLOUDS_DIR RESULTS_DIR
        [--methods bpa,poisson,o3d_ransac,o3d_patches,pcl_gp3] [--clouds A,B]
        [--voxel 0.1] [--repeat-real 3]

Every method reads the cloud from CLOUDS_DIR (manifest.json), times its own
computation (pre-processing such as normal estimation included, file I/O
excluded) and writes its output for the evaluation:
  mesh  -> RESULTS/NAME_CLOUD.mesh  (u32 nverts, u32 ntris, f32 xyz, u32 ijk)
  planes -> RESULTS/NAME_CLOUD.json + .labels (planes and a label per point)
  polygons -> RESULTS/NAME_CLOUD.json ({"polygons": [{"vertices"}]})
and RESULTS/peer_times.json (merged with earlier runs).

Size limits, so that a run stays bounded on 2 cores: on the simulated
locations (1.2 M points) the meshing peers (BPA, Poisson, PCL greedy
triangulation) and the segment_plane + DBSCAN loop run on the cloud
downsampled to one point per VOXEL (the centroid of each occupied voxel,
written by `repro_native pcd`); detect_planar_patches runs on every point.
The real scans (about 0.1 M points) are used whole by every method.
"""
import json
import os
import re
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

try:
    import open3d as o3d

    O3D = o3d.__version__
except Exception as e:  # noqa: BLE001
    o3d = None
    O3D = None
    O3D_WHY = f"open3d does not import ({e})"


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def arg(name, default):
    if f"--{name}" in sys.argv:
        return sys.argv[sys.argv.index(f"--{name}") + 1]
    return default


def read_bin(path):
    return np.fromfile(path, dtype="<f4").reshape(-1, 4)[:, :3].astype(np.float64)


def write_mesh(path, verts, tris):
    verts = np.asarray(verts, dtype="<f4").reshape(-1, 3)
    tris = np.asarray(tris, dtype="<u4").reshape(-1, 3)
    with open(path, "wb") as f:
        f.write(np.array([len(verts), len(tris)], dtype="<u4").tobytes())
        f.write(verts.tobytes())
        f.write(tris.tobytes())


def pcd_of(points):
    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    return pc


def normals(pc, viewpoint):
    pc.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=0.5, max_nn=30))
    pc.orient_normals_towards_camera_location(np.asarray(viewpoint, dtype=np.float64))


# --- methods ------------------------------------------------------------------


def m_bpa(points, viewpoint, out):
    t = time.perf_counter()
    pc = pcd_of(points)
    normals(pc, viewpoint)
    avg = float(np.mean(np.asarray(pc.compute_nearest_neighbor_distance())))
    radii = [1.5 * avg, 3 * avg, 6 * avg]
    mesh = o3d.geometry.TriangleMesh.create_from_point_cloud_ball_pivoting(
        pc, o3d.utility.DoubleVector(radii)
    )
    ms = 1e3 * (time.perf_counter() - t)
    write_mesh(out + ".mesh", np.asarray(mesh.vertices), np.asarray(mesh.triangles))
    return ms, {"kind": "mesh", "path": out + ".mesh", "triangles": len(mesh.triangles),
                "params": f"radii {', '.join(f'{r:.3f}' for r in radii)} m (1.5/3/6 x mean NN distance)"}


def m_poisson(points, viewpoint, out):
    t = time.perf_counter()
    pc = pcd_of(points)
    normals(pc, viewpoint)
    mesh, dens = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pc, depth=10)
    ms = 1e3 * (time.perf_counter() - t)
    v = np.asarray(mesh.vertices)
    tr = np.asarray(mesh.triangles)
    write_mesh(out + ".mesh", v, tr)
    # The common trimmed variant: drop vertices whose density is in the lowest 10 %.
    dens = np.asarray(dens)
    keep = dens >= np.quantile(dens, 0.10)
    tr2 = tr[keep[tr].all(axis=1)]
    write_mesh(out + "_trim.mesh", v, tr2)
    return ms, {"kind": "mesh", "path": out + ".mesh", "triangles": len(tr),
                "trimmed": {"kind": "mesh", "path": out + "_trim.mesh", "triangles": len(tr2)},
                "params": "depth 10"}


def m_o3d_ransac(points, viewpoint, out, planes=15):
    """15 x segment_plane (0.10 m, 1000 iterations), DBSCAN (eps 0.5 m, 10
    points) on each plane's inliers; every cluster of >= 150 points becomes a
    polygon (the convex hull of the cluster on the plane); all inliers leave."""
    t = time.perf_counter()
    o3d.utility.random.seed(7)
    n = len(points)
    remaining = np.arange(n)
    labels = np.full(n, 0xFFFFFFFF, dtype="<u4")
    out_planes = []
    for _ in range(planes):
        if len(remaining) < 3:
            break
        pc = pcd_of(points[remaining])
        model, inl = pc.segment_plane(distance_threshold=0.10, ransac_n=3, num_iterations=1000)
        inl = np.asarray(inl)
        if len(inl) < 3:
            break
        sub = pc.select_by_index(inl)
        lab = np.asarray(sub.cluster_dbscan(eps=0.5, min_points=10))
        for c in range(lab.max() + 1 if len(lab) else 0):
            members = inl[lab == c]
            if len(members) >= 150:
                labels[remaining[members]] = len(out_planes)
                out_planes.append({"normal": list(map(float, model[:3])), "offset": float(model[3]),
                                   "inliers": int(len(members))})
        mask = np.ones(len(remaining), dtype=bool)
        mask[inl] = False
        remaining = remaining[mask]
    ms = 1e3 * (time.perf_counter() - t)
    labels.tofile(out + ".labels")
    doc = {"planes": out_planes, "labels": os.path.basename(out) + ".labels"}
    return ms, {"kind": "planes", "path": out + ".json", "doc": doc, "polygons": len(out_planes),
                "params": "15 planes, 0.10 m, 1000 iterations; DBSCAN eps 0.5 m, min 10 points; clusters >= 150 points"}


def m_o3d_patches(points, viewpoint, out):
    t = time.perf_counter()
    pc = pcd_of(points)
    pc.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=0.5, max_nn=30))
    boxes = pc.detect_planar_patches(
        normal_variance_threshold_deg=60, coplanarity_deg=75, outlier_ratio=0.75,
        min_plane_edge_length=0, min_num_points=0,
        search_param=o3d.geometry.KDTreeSearchParamKNN(knn=30))
    ms = 1e3 * (time.perf_counter() - t)
    polys = []
    for b in boxes:
        c = np.asarray(b.center)
        R = np.asarray(b.R)
        e = np.asarray(b.extent)
        k = int(np.argmin(e))
        i, j = [a for a in range(3) if a != k]
        a = R[:, i] * e[i] / 2
        bb = R[:, j] * e[j] / 2
        verts = [c - a - bb, c + a - bb, c + a + bb, c - a + bb]
        polys.append({"vertices": [list(map(float, v)) for v in verts]})
    doc = {"polygons": polys}
    return ms, {"kind": "polygons", "path": out + ".json", "doc": doc, "polygons": len(polys),
                "params": "normals r 0.5 m / 30 NN; Open3D's documented defaults (60/75 deg, outlier ratio 0.75, KNN 30)"}


def parse_vtk(path):
    """Points and polygons of a legacy ASCII VTK POLYDATA file (what
    pcl_gp3_surface writes); polygons are fanned into triangles."""
    with open(path) as f:
        text = f.read()
    heads = list(re.finditer(r"^([A-Z_]+)( [^\n]*)?$", text, re.M))
    sections = {}
    for k, h in enumerate(heads):
        end = heads[k + 1].start() if k + 1 < len(heads) else len(text)
        sections.setdefault(h.group(1), (h.group(2) or "", text[h.end():end]))
    n = int(sections["POINTS"][0].split()[0])
    verts = np.array(sections["POINTS"][1].split(), dtype=np.float64)[: 3 * n].reshape(-1, 3)
    m_poly = int(sections["POLYGONS"][0].split()[0])
    nums = np.array(sections["POLYGONS"][1].split(), dtype=np.int64)
    if m_poly and np.all(nums[0::4][:m_poly] == 3) and len(nums) == 4 * m_poly:
        return verts, nums.reshape(-1, 4)[:, 1:]
    tris = []
    k = 0
    for _ in range(m_poly):
        c = nums[k]
        ids = nums[k + 1: k + 1 + c]
        for q in range(1, c - 1):
            tris.append((ids[0], ids[q], ids[q + 1]))
        k += 1 + c
    return verts, np.array(tris, dtype=np.int64).reshape(-1, 3)


def m_pcl_gp3(pcd_path, viewpoint, out):
    """pcl_normal_estimation (k 20) then pcl_gp3_surface (radius 0.5 m, mu
    2.5); the time is what the two tools report for their computation."""
    normals_pcd = out + "_normals.pcd"
    vtk = out + ".vtk"
    r1 = subprocess.run(["pcl_normal_estimation", pcd_path, normals_pcd, "-k", "20"],
                        capture_output=True, text=True, timeout=900)
    m1 = re.search(r"Computed normals in ([\d.]+) ms", r1.stdout + r1.stderr)
    r2 = subprocess.run(["pcl_gp3_surface", normals_pcd, vtk, "-radius", "0.5", "-mu", "2.5"],
                        capture_output=True, text=True, timeout=1800)
    m2 = re.findall(r"\[done, ([\d.]+) ms : \d+ polygons\]", r2.stdout + r2.stderr)
    if not (m1 and m2 and os.path.exists(vtk)):
        raise RuntimeError("pcl tools failed: " + (r1.stderr + r2.stdout + r2.stderr)[-400:])
    ms = float(m1.group(1)) + float(m2[0])
    v, t = parse_vtk(vtk)
    write_mesh(out + ".mesh", v, t)
    for f in (normals_pcd, vtk):
        os.remove(f)
    return ms, {"kind": "mesh", "path": out + ".mesh", "triangles": len(t),
                "params": "normals k 20; search radius 0.5 m, mu 2.5"}


METHODS = {
    "bpa": ("Open3D ball pivoting", m_bpa, True),
    "poisson": ("Open3D Poisson", m_poisson, True),
    "o3d_ransac": ("Open3D segment_plane x15 + DBSCAN", m_o3d_ransac, True),
    "o3d_patches": ("Open3D detect_planar_patches", m_o3d_patches, False),
    "pcl_gp3": ("PCL greedy projection triangulation", m_pcl_gp3, True),
}


def pcl_version():
    try:
        out = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "pcl-tools"],
                             capture_output=True, text=True).stdout.strip()
        return out or None
    except Exception:  # noqa: BLE001
        return None


def main():
    clouds_dir, res = sys.argv[1], sys.argv[2]
    os.makedirs(res, exist_ok=True)
    methods = arg("methods", ",".join(METHODS)).split(",")
    only = arg("clouds", None)
    only = only.split(",") if only else None
    voxel = float(arg("voxel", "0.1"))
    rep_real = int(arg("repeat-real", "3"))
    native = os.path.join(ROOT, os.environ.get("CARGO_TARGET_DIR", "target"), "release/examples/repro_native")
    manifest = json.load(open(os.path.join(clouds_dir, "manifest.json")))
    tpath = os.path.join(res, "peer_times.json")
    times = json.load(open(tpath)) if os.path.exists(tpath) else {"results": []}
    has_pcl = subprocess.run(["sh", "-c", "command -v pcl_gp3_surface"], capture_output=True).returncode == 0
    times["open3d"] = O3D
    times["open3d_why"] = None if O3D else O3D_WHY
    times["pcl_tools"] = pcl_version() if has_pcl else None
    times["voxel"] = voxel
    for c in manifest["clouds"]:
        if only and c["name"] not in only:
            continue
        sim = c["kind"] == "sim"
        full = read_bin(c["bin"])
        small_bin = os.path.join(clouds_dir, f"{c['name']}_v{int(voxel * 100)}.bin")
        small_pcd = small_bin[:-4] + ".pcd"
        full_pcd = os.path.join(clouds_dir, f"{c['name']}_full.pcd")
        if sim and not os.path.exists(small_pcd):
            subprocess.run([native, "pcd", c["bin"], small_pcd, "--voxel", str(voxel), "--bin", small_bin], check=True)
        if not sim and "pcl_gp3" in methods and has_pcl and not os.path.exists(full_pcd):
            subprocess.run([native, "pcd", c["bin"], full_pcd], check=True)
        small = read_bin(small_bin) if sim else full
        for key in methods:
            label, fn, downsample = METHODS[key]
            entry = {"cloud": c["name"], "method": key, "label": label}
            use_small = sim and downsample
            entry["inputPoints"] = int(len(small) if use_small else len(full))
            entry["downsampled"] = bool(use_small)
            if key == "pcl_gp3" and not has_pcl:
                entry["skipped"] = "pcl-tools (pcl_gp3_surface) is not installed"
            elif key != "pcl_gp3" and o3d is None:
                entry["skipped"] = O3D_WHY
            else:
                out = os.path.join(res, f"{key}_{c['name']}")
                reps = rep_real if (not sim and key == "o3d_patches") else 1
                runs = []
                try:
                    for r in range(reps):
                        if key == "pcl_gp3":
                            ms, info = fn(small_pcd if use_small else full_pcd, c["viewpoint"], out)
                        else:
                            ms, info = fn(small if use_small else full, c["viewpoint"], out)
                        runs.append(ms)
                        log(f"  {key:12} {c['name']:8} run {r + 1}/{reps}: {ms:10.1f} ms"
                            f" ({entry['inputPoints']} points{', downsampled' if use_small else ''})")
                    doc = info.pop("doc", None)
                    if doc is not None:
                        if use_small and info["kind"] == "planes":
                            doc["points"] = os.path.relpath(small_bin, res)
                        json.dump(doc, open(info["path"], "w"))
                    entry.update(info)
                    entry["timesMs"] = runs
                    entry["medianMs"] = float(np.median(runs))
                except Exception as e:  # noqa: BLE001
                    entry["skipped"] = f"failed: {e}"
                    log(f"  {key} {c['name']}: failed: {e}")
            times["results"] = [x for x in times["results"]
                                if not (x["cloud"] == c["name"] and x["method"] == key)]
            times["results"].append(entry)
            json.dump(times, open(tpath, "w"), indent=1)


if __name__ == "__main__":
    main()
