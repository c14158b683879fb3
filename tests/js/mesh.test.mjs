// The triangulated outlines are a valid indexed mesh covering exactly the
// polygons.
import { test } from "node:test";
import assert from "node:assert/strict";
import { ps, psSim } from "./common.mjs";

test("mesh(): indices in range, one polygon id per triangle, areas and orientation match", () => {
  const sim = psSim.simulate({ layout: "crossing", seed: 4 });
  const scenario = new ps.Scenario({ hull: "concave" });
  for (let k = 0; k < 6; k++) {
    const s = sim.next();
    scenario.addScan(s.points, { stride: s.stride, pose: s.pose });
  }
  sim.free();
  const polygons = scenario.polygons();
  const mesh = scenario.mesh();
  scenario.free();
  assert.ok(polygons.length >= 5, `${polygons.length} polygons`);
  assert.ok(mesh.positions instanceof Float32Array);
  assert.ok(mesh.indices instanceof Uint32Array);
  assert.ok(mesh.polygonIds instanceof Uint32Array);
  assert.equal(mesh.positions.length % 3, 0);
  assert.equal(mesh.indices.length % 3, 0);
  const nv = mesh.positions.length / 3;
  const nt = mesh.indices.length / 3;
  assert.equal(mesh.polygonIds.length, nt);
  assert.ok(mesh.indices.every((i) => i < nv), "indices in range");
  assert.equal(mesh.origin.length, 3);
  assert.ok(mesh.origin.every((c) => Number.isInteger(c)), "origin in whole metres");

  const byId = new Map(polygons.map((p) => [p.id, p]));
  const area = new Map();
  let facingChecked = 0;
  const p = (i) => [0, 1, 2].map((c) => mesh.positions[3 * i + c] + mesh.origin[c]);
  for (let t = 0; t < nt; t++) {
    const poly = byId.get(mesh.polygonIds[t]);
    assert.ok(poly, `triangle ${t} has an existing polygon id`);
    const [a, b, c] = [0, 1, 2].map((k) => p(mesh.indices[3 * t + k]));
    const u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    const v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    const n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    const twice = Math.hypot(...n);
    // Counter-clockwise seen from the polygon's normal side. (Slivers between
    // nearly collinear outline vertices have no reliable direction in f32.)
    const facing = (n[0] * poly.normal[0] + n[1] * poly.normal[1] + n[2] * poly.normal[2]) / twice;
    if (twice > 2e-4) {
      assert.ok(facing > 0.999, `triangle ${t} faces its polygon's normal (${facing})`);
      facingChecked++;
    }
    // Every vertex lies on the polygon's plane.
    for (const q of [a, b, c]) {
      const d = q[0] * poly.normal[0] + q[1] * poly.normal[1] + q[2] * poly.normal[2] + poly.offset;
      assert.ok(Math.abs(d) < 1e-3, `vertex off the plane by ${d}`);
    }
    area.set(poly.id, (area.get(poly.id) ?? 0) + twice / 2);
  }
  assert.ok(facingChecked > 0.9 * nt, `${facingChecked} of ${nt} triangles are not slivers`);
  let total = 0;
  let want = 0;
  for (const poly of polygons) {
    const got = area.get(poly.id) ?? 0;
    assert.ok(Math.abs(got - poly.area) <= 1e-4 * poly.area + 1e-3, `polygon ${poly.id}: ${got} vs ${poly.area} m^2`);
    total += got;
    want += poly.area;
  }
  assert.ok(Math.abs(total - want) <= 1e-4 * want, `total ${total} vs ${want} m^2`);
});
