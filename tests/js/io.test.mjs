// polyscene/io (js/io.mjs): LAS (1.2 through @loaders.gl/las, 1.4 read
// here) and LAZ in UTM coordinates, PCD (ascii, binary float64 at UTM,
// binary_compressed), PLY (ascii, binary little-endian float64 at UTM,
// binary big-endian) and a KITTI sequence with calib.txt each give the
// polygons of the same points given as a raw .bin in a local frame, to 1 mm
// once moved back (tests/cli.rs's criterion); bad files are errors that
// name the file and the problem.
import test from "node:test";
import assert from "node:assert/strict";
import { register } from "node:module";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { cli, ps, psSim, repoRoot, tempDir } from "./common.mjs";
import * as fx from "./io-fixtures.mjs";

register("./resolve-www.mjs", import.meta.url);
const io = await import("../../js/io.mjs");

/** Scan 0 of the simulated street, on a 1/1024 m grid (exact in every format). */
const sim = psSim.simulate({ layout: "street", seed: 1 });
const POINTS = fx.onGrid(sim.scan(0).points, 4);
sim.free();
const LOCAL_BIN = fx.rawBin(POINTS);

/** The same polygons, to 1 mm, once `got` is moved back by `shift`. */
export function assertSamePolygons(what, got, shift, want) {
  assert.equal(got.length, want.length, `${what}: polygon count`);
  got.forEach((p, k) => {
    const q = want[k];
    assert.equal(p.vertices.length, q.vertices.length, `${what}: polygon ${k} vertex count`);
    for (let j = 0; j < p.vertices.length; j++) {
      const d = Math.abs(p.vertices[j] - shift[j % 3] - q.vertices[j]);
      assert.ok(d <= 1e-3, `${what}: polygon ${k} value ${j}: ${p.vertices[j] - shift[j % 3]} vs ${q.vertices[j]}`);
    }
    for (let j = 0; j < 3; j++) assert.ok(Math.abs(p.normal[j] - q.normal[j]) < 1e-6, `${what}: polygon ${k} normal`);
    assert.ok(Math.abs(p.area - q.area) < 1e-3, `${what}: polygon ${k} area`);
  });
}

/** A LAZ file of the points moved by `shift`, written by the `las` crate (examples/write_las.rs). */
function laz(shift, dir) {
  const target = process.env.CARGO_TARGET_DIR ?? path.join(repoRoot, "target");
  const bin = path.join(target, "release", "examples", "write_las");
  if (!fs.existsSync(bin)) throw new Error(`${bin} is missing: build it with cargo build --release --example write_las (scripts/test-js.sh does)`);
  fs.writeFileSync(path.join(dir, "local.bin"), LOCAL_BIN);
  execFileSync(bin, [path.join(dir, "local.bin"), path.join(dir, "utm.laz"), shift.join(",")]);
  return fs.readFileSync(path.join(dir, "utm.laz"));
}

async function rejects(promise, ...patterns) {
  let caught;
  try {
    await promise;
  } catch (e) {
    caught = e;
  }
  assert.ok(caught instanceof Error, `expected an Error matching ${patterns.join(", ")}; got ${caught}`);
  for (const p of patterns) assert.match(caught.message, p);
  return caught;
}

test("every format gives the polygons of the raw local .bin, to 1 mm", async () => {
  const raw = await io.readKittiBin(LOCAL_BIN, { name: "local.bin" });
  assert.equal(raw.stride, 4);
  assert.ok(raw.points instanceof Float32Array);
  const want = ps.detect(raw.points, { stride: raw.stride, viewpoint: [0, 0, 0] });
  assert.ok(want.length >= 10, `${want.length} polygons`);

  const dir = tempDir("io");
  const wkt = 'PROJCS["WGS 84 / UTM zone 32N",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["latitude_of_origin",0],PARAMETER["central_meridian",9],PARAMETER["scale_factor",0.9996],PARAMETER["false_easting",500000],PARAMETER["false_northing",0],UNIT["metre",1],AUTHORITY["EPSG","32632"]]';
  const files = [
    ["utm-1.2.las", fx.las(POINTS, fx.UTM, { crs: { epsg: 32632 } }), "las", fx.UTM],
    ["utm-1.4.las", fx.las(POINTS, fx.UTM, { version: "1.4", crs: { wkt } }), "las", fx.UTM],
    ["utm.laz", laz(fx.UTM, dir), "laz", fx.UTM],
    ["ascii.pcd", fx.pcd(POINTS, "ascii"), "pcd", [0, 0, 0]],
    ["utm-binary.pcd", fx.pcd(POINTS, "binary", fx.UTM), "pcd", fx.UTM],
    ["compressed.pcd", fx.pcd(POINTS, "compressed"), "pcd", [0, 0, 0]],
    ["ascii.ply", fx.ply(POINTS, "ascii"), "ply", [0, 0, 0]],
    ["utm-binary.ply", fx.ply(POINTS, "le64", fx.UTM), "ply", fx.UTM],
    ["big-endian.ply", fx.ply(POINTS, "be32"), "ply", [0, 0, 0]],
  ];
  for (const [name, bytes, format, shift] of files) {
    // A File (as a browser's file input gives) names itself.
    const cloud = await io.readPoints(new File([bytes], name));
    assert.equal(cloud.format, format, name);
    assert.equal(cloud.name, name);
    assert.equal(cloud.count, POINTS.length, `${name}: points (the NaN point of ascii.pcd left out)`);
    assert.equal(cloud.stride, 3);
    // Map coordinates stay float64; float32 fields stay float32.
    assert.ok(cloud.points instanceof (shift[0] ? Float64Array : Float32Array), `${name}: ${cloud.points.constructor.name}`);
    const got = ps.detect(cloud.points, { stride: cloud.stride, viewpoint: shift });
    assertSamePolygons(name, got, shift, want);
  }
  // The ascii PLY's size is a multiple of 16, yet it is read as PLY.
  assert.equal(files[6][1].length % 16, 0);
});

test("points made with 4 values a point (a KITTI .bin, a simulated scan) are refused without { stride: 4 }, not read as x, y, z", async () => {
  const raw = await io.readKittiBin(LOCAL_BIN, { name: "local.bin" });
  const sim = psSim.simulate({ layout: "street", seed: 1 }).scan(0);
  for (const points of [raw.points, sim.points]) {
    const mark = Object.getOwnPropertyDescriptor(points, "stride");
    assert.equal(mark.value, 4);
    assert.equal(mark.enumerable, false, "not among the array's keys");
    const refused = (call) =>
      assert.throws(call, (e) => e instanceof Error && /option 'stride': not given/.test(e.message) && /pass \{ stride: 4 \}/.test(e.message));
    refused(() => ps.detect(points));
    refused(() => ps.detectFlat(points, { viewpoint: [0, 0, 0] }));
    const scenario = new ps.Scenario();
    refused(() => scenario.addScan(points, { pose: sim.pose }));
    assert.equal(scenario.scans, 0, "a refused scan is not counted");
    // Given, the stride is read as given.
    assert.ok(scenario.addScan(points, { stride: 4, pose: sim.pose }).polygonCount > 0);
    scenario.free();
  }
  // Points of stride 3 carry no mark (LAS, PCD, PLY give x, y, z).
  assert.equal(Object.getOwnPropertyDescriptor(new Float32Array(raw.points), "stride"), undefined);
});

test("LAS: the CRS of its GeoTIFF keys or WKT record comes back, ready for polyscene/geo", async () => {
  const keys = await io.readPoints(fx.las(POINTS.slice(0, 100), fx.UTM, { crs: { epsg: 32632 } }));
  assert.equal(keys.crs.epsg, 32632);
  assert.equal(keys.crs.definition, "EPSG:32632");
  const wkt = 'PROJCS["NAD83 / UTM zone 17N",GEOGCS["NAD83",AUTHORITY["EPSG","4269"]],AUTHORITY["EPSG","26917"]]';
  const w = await io.readPoints(fx.las(POINTS.slice(0, 100), fx.UTM, { version: "1.4", crs: { wkt } }));
  assert.equal(w.crs.wkt, wkt);
  assert.equal(w.crs.definition, "EPSG:26917", "the WKT's own authority, not its datum's");
  const none = await io.readPoints(fx.las(POINTS.slice(0, 100), fx.UTM));
  assert.equal(none.crs, undefined);
  // polyscene/geo places the first point by that CRS.
  const geo = await import("../../js/geo.mjs");
  const frame = geo.geoFrame({ crs: keys.crs.definition });
  const [lon, lat] = frame.toLonLat(keys.points[0], keys.points[1], keys.points[2]);
  assert.ok(Math.abs(lon - 9) < 0.01 && Math.abs(lat - 40.65) < 0.01, `${lon}, ${lat}`);
});

test("a KITTI sequence with calib.txt gives the map of its LiDAR poses; without calib it is refused", async () => {
  const drive = psSim.simulate({ layout: "street", seed: 2 });
  const n = 6;
  const scans = [];
  for (let k = 0; k < n; k++) scans.push(drive.scan(k));
  drive.free();
  const map = (list) => {
    const s = new ps.Scenario();
    for (const { points, pose } of list) s.addScan(points, { stride: 4, pose });
    const polygons = s.polygons();
    s.free();
    return polygons;
  };
  const want = map(scans);
  assert.ok(want.length >= 10, `${want.length} polygons`);

  // KITTI's layout: camera-0 poses Tr . L . Tr^-1, calib.txt, NNNNNN.bin.
  const tr = fx.calibTr();
  const cameraPoses = scans.map((s) => fx.poseLine(fx.mat4Mul(fx.mat4Mul(tr, Float64Array.from(s.pose)), fx.mat4Inverse(tr)))).join("\n") + "\n";
  const bins = scans.map((s, k) => ({
    path: `dataset/sequences/00/velodyne/${String(k).padStart(6, "0")}.bin`,
    data: new Uint8Array(s.points.buffer, s.points.byteOffset, s.points.byteLength),
  }));
  const folder = [
    ...bins,
    { path: "dataset/sequences/00/calib.txt", data: new TextEncoder().encode(fx.CALIB_00) },
    { path: "dataset/poses/00.txt", data: new TextEncoder().encode(cameraPoses) },
  ];
  const read = async (seq) => {
    const out = [];
    for await (const scan of seq) {
      assert.equal(scan.stride, 4);
      out.push(scan);
    }
    return out;
  };
  // From the parts (as File objects), and found in the folder's layout.
  const seq = await io.kittiSequence({
    scans: bins.map((b) => new File([b.data], path.basename(b.path))),
    poses: new File([cameraPoses], "00.txt"),
    calib: fx.CALIB_00,
  });
  assert.equal(seq.length, n);
  const fromParts = await read(seq);
  fromParts.forEach((s, k) => {
    for (let i = 0; i < 16; i++) assert.ok(Math.abs(s.pose[i] - scans[k].pose[i]) < 1e-9, `scan ${k} pose[${i}]`);
  });
  assertSamePolygons("kittiSequence", map(fromParts), [0, 0, 0], want);
  const found = await io.findKittiSequence(folder);
  assertSamePolygons("findKittiSequence", map(await read(found)), [0, 0, 0], want);

  // Camera poses read as LiDAR poses: another (wrong) map.
  const wrong = await io.kittiSequence({ scans: bins.map((b) => ({ name: b.path, data: b.data })), poses: cameraPoses, lidarPoses: true });
  assert.notDeepEqual(map(await read(wrong)).map((p) => p.area), want.map((p) => p.area));

  // No calib: refused, naming both ways out.
  await rejects(io.kittiSequence({ scans: bins.map((b) => ({ name: b.path, data: b.data })), poses: cameraPoses }), /camera-0 poses/, /calib/, /lidarPoses/);
  await rejects(io.findKittiSequence(folder.filter((f) => !f.path.endsWith("calib.txt"))), /poses\/00\.txt/, /calib\.txt/, /lidarPoses/);
  // Missing scan, one pose too few, a name that is no scan number.
  await rejects(io.findKittiSequence(folder.filter((f) => !f.path.endsWith("000002.bin"))), /000002\.bin is missing/, /skipMissing/);
  const fewer = cameraPoses.split("\n").slice(0, 4).join("\n");
  await rejects(io.kittiSequence({ scans: bins.map((b) => ({ name: b.path, data: b.data })), poses: fewer, calib: fx.CALIB_00, posesName: "00.txt" }), /00\.txt/, /4 poses for scans numbered 0 to 5/);
  await rejects(io.kittiSequence({ scans: [{ name: "scan.bin", data: bins[0].data }], poses: cameraPoses, calib: fx.CALIB_00 }), /scan\.bin/, /NNNNNN\.bin/);
  // A flat folder with calib.txt beside its poses: which frame is asked for.
  const flat = bins.map((b) => ({ path: `drive/${path.basename(b.path)}`, data: b.data }));
  flat.push({ path: "drive/poses.txt", data: cameraPoses }, { path: "drive/calib.txt", data: fx.CALIB_00 });
  await rejects(io.findKittiSequence(flat), /drive\/calib\.txt/, /lidarPoses/);
  assertSamePolygons("flat folder, calib given", map(await read(await io.findKittiSequence(flat, { calib: fx.CALIB_00 }))), [0, 0, 0], want);
});

test("calib and poses: Tr^-1 . P . Tr, the raw data's R and T, and rigidity checks", () => {
  const tr = io.parseKittiCalib(fx.CALIB_00);
  // LiDAR x (forward) is camera z.
  assert.ok(Math.abs(tr[2] - 1) < 1e-2 && Math.abs(tr[0]) < 1e-2, `${tr.slice(0, 3)}`);
  const raw = io.parseKittiCalib("R: 1 0 0 0 0 -1 0 1 0\nT: 0.1 0.2 0.3\n");
  assert.deepEqual([...raw.slice(12, 15)], [0.1, 0.2, 0.3]);
  assert.deepEqual([...raw.slice(0, 12)], [1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0]);
  assert.throws(() => io.parseKittiCalib("P0: 1 2 3\n", { name: "calib.txt" }), /calib\.txt.*no LiDAR-to-camera transform/);
  assert.throws(() => io.parseKittiCalib("Tr: 1 0 0\n"), /expected 12 numbers, found 3/);
  assert.throws(() => io.parseKittiCalib("Tr: 2 0 0 0 0 1 0 0 0 0 1 0\n"), /not orthonormal/);
  assert.throws(() => io.parseKittiPoses("1 0 0 0 0 1 0 0 0 0 -1 0\n", { name: "00.txt" }), /00\.txt: poses line 1: .*reflection/);
  assert.throws(() => io.parseKittiPoses("1 0 0 0 0 1 0 0 0 0 1 x\n"), /"x" is not a number/);
  // A LiDAR pose converts to the camera pose and back exactly.
  const lidar = Float64Array.from([Math.cos(0.3), Math.sin(0.3), 0, 0, -Math.sin(0.3), Math.cos(0.3), 0, 0, 0, 0, 1, 0, 4, 0.5, 0.02, 1]);
  const camera = fx.mat4Mul(fx.mat4Mul(tr, lidar), fx.mat4Inverse(tr));
  const [back] = io.kittiLidarPoses([camera], tr);
  for (let i = 0; i < 16; i++) assert.ok(Math.abs(back[i] - lidar[i]) < 1e-12, `[${i}] ${back[i]} vs ${lidar[i]}`);
});

test("bad files are errors naming the file and the problem, never an empty result", async () => {
  const check = (name, bytes, options, ...problems) => rejects(io.readPoints(new File([bytes], name), options), new RegExp(name.replace(".", "\\.")), ...problems);
  await check("empty.las", new Uint8Array(0), {}, /empty file \(0 bytes\)/);
  await rejects(io.readKittiBin(new Uint8Array(0), { name: "000000.bin" }), /000000\.bin: empty file/);
  await check("odd.bin", new Uint8Array(20), { stride: 4 }, /not a multiple of 16/);
  await rejects(io.readKittiBin(new Uint8Array(20), { name: "odd.bin" }), /odd\.bin.*20 bytes is not a multiple of 16/);
  await check("nostride.bin", new Uint8Array(32), {}, /stride: 4/);
  const nan = new Float32Array([1, 2, 3, 0.5, 1, NaN, 3, 0.5]);
  await rejects(io.readKittiBin(nan, { name: "nan.bin" }), /nan\.bin: point 1 has a NaN/);
  await check("points.xyz", new TextEncoder().encode("1.0 2.0 3.0\n4.0 5.0 6.0\n"), { stride: 3 }, /text file/);
  await check("cloud.bin.gz", Uint8Array.from([0x1f, 0x8b, 8, 0, 0, 0, 0, 0]), { stride: 4 }, /gzip/);

  // A PLY whose size is a multiple of 16 is no KITTI .bin.
  const ply = fx.ply(POINTS.slice(0, 500), "ascii");
  assert.equal(ply.length % 16, 0);
  await rejects(io.readKittiBin(new File([ply], "000000.bin")), /000000\.bin: a PLY file, not a KITTI \.bin/);

  // LAS: cut short, header only, wrong version; LAZ cut short.
  const las = fx.las(POINTS.slice(0, 2000), fx.UTM);
  await check("cut.las", las.subarray(0, las.length - 100), {}, /promises 2000 points, the file holds 1995/, /truncated/);
  await check("header.las", las.subarray(0, 50), {}, /LAS header cut short/);
  const v2 = las.slice();
  v2[24] = 2;
  await check("v2.las", v2, {}, /LAS version 2\.2/);
  const lazBytes = laz(fx.UTM, tempDir("io-bad"));
  await check("cut.laz", lazBytes.subarray(0, lazBytes.length >> 1), {}, /LAZ/);

  // PLY and PCD without z, or cut short; a bad magic after "ply".
  const text = (s) => new TextEncoder().encode(s);
  await check("noz.ply", text("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nend_header\n1 2\n3 4\n"), {}, /no 'z'/);
  await check("short.ply", text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n"), {}, /the PLY header promises 3 vertices; 6 bytes of data cannot hold them/);
  await check("short2.ply", text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n1.000 2.000 3.000\n4.000 5.000 6.000\n"), {}, /PLY vertex 2 of 3: the file ends there/);
  await check("huge.ply", text("ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty double x\nproperty double y\nproperty double z\nend_header\n"), {}, /PLY vertex 0 of 4000000000: the file ends there/);
  await check("huge.pcd", text("VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 4000000000\nHEIGHT 1\nPOINTS 4000000000\nDATA ascii\n1 2 3\n"), {}, /promises 4000000000 points; 6 bytes of data cannot hold them/);
  const le = fx.ply(POINTS.slice(0, 100), "le64", fx.UTM);
  await check("short-binary.ply", le.subarray(0, le.length - 8), {}, /PLY vertex 99 of 100: the file ends there/);
  await check("novertex.ply", text("ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n"), {}, /a PLY file with no points/);
  await check("allnan.pcd", text("VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\nnan nan nan\nnan nan nan\n"), {}, /a PCD file with no points/);
  await check("noend.ply", text("ply\nformat ascii 1.0\nelement vertex 1\n"), {}, /end_header/);
  await check("noz.pcd", text("VERSION .7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2\n"), {}, /no 'z'/);
  await check("short.pcd", text("VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA binary\n\0\0\0\0"), {}, /PCD point 0 of 3: the file ends there/);
  const packed = fx.pcd(POINTS.slice(0, 300), "compressed");
  await check("cut-compressed.pcd", packed.subarray(0, packed.length - 10), {}, /compressed bytes promised/);
  // Damaged LZF data: a back reference before the start.
  const bad = packed.slice();
  const dataStart = new TextDecoder().decode(packed.subarray(0, 400)).indexOf("binary_compressed\n") + "binary_compressed\n".length;
  bad[dataStart + 8] = 0x20; // the first LZF op: a back reference, with nothing written yet
  await check("damaged.pcd", bad, {}, /LZF data is damaged/);

  // Not bytes.
  await assert.rejects(io.readPoints("cloud.las"), /must be bytes.*polyscene\/io\/node/);
});

test("the LZF decoder of binary_compressed PCD reads back references and literal runs", async () => {
  const data = new Uint8Array(5000);
  for (let i = 0; i < data.length; i++) data[i] = (i * 7) % 13 === 0 ? i & 0xff : 42;
  const packed = fx.lzfCompress(data);
  assert.ok(packed.length < data.length / 2, `${packed.length} bytes: back references used`);
  // Through a PCD of one u8 field per coordinate.
  const n = data.length / 5;
  const head = `VERSION 0.7\nFIELDS x y z a b\nSIZE 1 1 1 1 1\nTYPE U U U U U\nCOUNT 1 1 1 1 1\nWIDTH ${n}\nHEIGHT 1\nPOINTS ${n}\nDATA binary_compressed\n`;
  const sizes = new Uint8Array(8);
  new DataView(sizes.buffer).setUint32(0, packed.length, true);
  new DataView(sizes.buffer).setUint32(4, data.length, true);
  const file = new Uint8Array([...new TextEncoder().encode(head), ...sizes, ...packed]);
  const cloud = await io.readPoints(file);
  assert.ok(cloud.points instanceof Float64Array, "integer fields are float64");
  for (let k = 0; k < n; k++) {
    for (let a = 0; a < 3; a++) assert.equal(cloud.points[3 * k + a], data[a * n + k], `point ${k} axis ${a}`);
  }
});

test("polyscene/io/node: a KITTI dataset root on disk gives the CLI's replay map, to 1 mm (the conventions of src/io/kitti.rs); files by path", async () => {
  const node = await import("../../js/io-node.mjs");
  const dir = tempDir("io-kitti");
  const drive = psSim.simulate({ layout: "street", seed: 2 });
  const tr = fx.calibTr();
  const root = path.join(dir, "dataset");
  const seq = path.join(root, "sequences", "00");
  fs.mkdirSync(path.join(seq, "velodyne"), { recursive: true });
  fs.mkdirSync(path.join(root, "poses"));
  const lines = [];
  for (let k = 0; k < 5; k++) {
    const s = drive.scan(k);
    fs.writeFileSync(path.join(seq, "velodyne", `${String(k).padStart(6, "0")}.bin`), new Uint8Array(s.points.buffer, s.points.byteOffset, s.points.byteLength));
    lines.push(fx.poseLine(fx.mat4Mul(fx.mat4Mul(tr, Float64Array.from(s.pose)), fx.mat4Inverse(tr))));
  }
  drive.free();
  fs.writeFileSync(path.join(root, "poses", "00.txt"), lines.join("\n") + "\n");
  fs.writeFileSync(path.join(seq, "calib.txt"), fx.CALIB_00);

  const want = JSON.parse(cli("replay", root, "--sequence", "00")).polygons.map((p) => ({ ...p, vertices: p.vertices.flat() }));
  assert.ok(want.length >= 10, `${want.length} polygons`);
  const scenario = new ps.Scenario(); // the CLI's defaults
  const sequence = await node.openKittiSequence(root); // one sequence: no need to name it
  assert.equal(sequence.length, 5);
  for await (const scan of sequence) scenario.addScan(scan.points, { stride: scan.stride, pose: scan.pose });
  assertSamePolygons("openKittiSequence vs polyscene replay", scenario.polygons(), [0, 0, 0], want);
  scenario.free();
  // The sequence folder itself, and its refusal without calib.txt.
  assert.equal((await node.openKittiSequence(seq)).length, 5);
  fs.renameSync(path.join(seq, "calib.txt"), path.join(dir, "calib-00.txt"));
  await rejects(node.openKittiSequence(root), /00\.txt/, /calib\.txt/, /lidarPoses/);
  assert.equal((await node.openKittiSequence(root, { calib: path.join(dir, "calib-00.txt") })).length, 5);

  // Point files by path; a missing one names itself.
  const las = path.join(dir, "utm.las");
  fs.writeFileSync(las, fx.las(POINTS.slice(0, 1000), fx.UTM, { crs: { epsg: 32633 } }));
  const cloud = await node.readPointsFile(las);
  assert.equal(cloud.count, 1000);
  assert.equal(cloud.crs.definition, "EPSG:32633");
  assert.equal(cloud.name, las);
  await rejects(node.readPointsFile(path.join(dir, "none.las")), /none\.las: cannot read/);
});
