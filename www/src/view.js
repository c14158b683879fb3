// SceneView: the three.js view of a live polyscene run. It draws the current
// scan (points coloured by the polygon that explained them), the polygons
// (filled, semi-transparent surfaces from Scenario.mesh() and crisp outlines
// from Scenario.polygons()), the vehicle and its trail, and answers picks.
//
// GPU buffers are allocated once at a maximum size and updated in place
// (setDrawRange + update ranges); a buffer is re-allocated only when a scan or
// a mesh exceeds it (then at twice the size). Everything is drawn relative to
// a local origin (the first pose of a run), computed in f64 before the f32
// upload, so geo-referenced coordinates keep centimetre precision.
//
// The world frame is z-up (as the library's); the camera's up is +z.
//
//   const view = new SceneView(container);
//   view.reset();
//   view.showScan({ points, labels, pose, polygons, mesh });  // a worker 'scan' message
//   view.addEventListener('pick', (e) => console.log(e.detail)); // polygon or null

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { LineSegments2 } from 'three/addons/lines/LineSegments2.js';
import { LineSegmentsGeometry } from 'three/addons/lines/LineSegmentsGeometry.js';
import { LineMaterial } from 'three/addons/lines/LineMaterial.js';
import { idColor, colorPoints } from './palette.js';

const BG = 0x0b0f16;

// What you write is what you see: palette bytes and hex colours are shown as
// given (sRGB), without linear-space conversions (a data view, not a photo).
THREE.ColorManagement.enabled = false;

/** Is WebGL done in software here (SwiftShader, llvmpipe)? */
function isSoftwareGL() {
  try {
    const gl = document.createElement('canvas').getContext('webgl2');
    if (!gl) return false;
    const info = gl.getExtension('WEBGL_debug_renderer_info');
    const name = info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
    gl.getExtension('WEBGL_lose_context')?.loseContext();
    return /swiftshader|llvmpipe|software/i.test(String(name));
  } catch {
    return false;
  }
}

function nextPow2(n) {
  return 2 ** Math.ceil(Math.log2(Math.max(n, 1)));
}

export class SceneView extends EventTarget {
  constructor(
    container,
    {
      maxPoints = 1 << 18, // 262,144: an HDL-64E scan is ~120k, an OS0-128 ~130k
      maxMeshVertices = 1 << 16,
      maxMeshIndices = 1 << 18,
      maxOutlineSegments = 1 << 15,
      maxTrail = 1 << 14,
      preserveDrawingBuffer = false,
    } = {},
  ) {
    super();
    this.container = container;
    this.settings = {
      pointSize: 2.0,
      showPoints: true,
      showSurfaces: true,
      showOutlines: true,
      surfaceOpacity: 0.5,
      follow: true,
    };
    this.origin = null; // [x, y, z] f64, world position of the local frame
    this.polygonsById = new Map();
    this.groundIds = new Set();
    this.polygonIds = new Uint32Array(0); // per triangle of the surface mesh
    this.vehiclePose = null;
    this.selectedId = null;
    this.groundZ = null;

    // Software WebGL (SwiftShader: headless browsers, machines without a GPU)
    // gets no MSAA and a pixel ratio of 1, or it renders a frame a second.
    this.software = isSoftwareGL();
    const renderer = new THREE.WebGLRenderer({ antialias: !this.software, preserveDrawingBuffer, powerPreference: 'high-performance' });
    renderer.setPixelRatio(this.software ? 1 : Math.min(window.devicePixelRatio || 1, 2));
    renderer.setClearColor(BG, 1);
    renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
    container.appendChild(renderer.domElement);
    renderer.domElement.tabIndex = 0;
    this.renderer = renderer;

    const scene = new THREE.Scene();
    scene.fog = new THREE.Fog(BG, 160, 420);
    this.scene = scene;

    const camera = new THREE.PerspectiveCamera(50, 1, 0.1, 4000);
    camera.up.set(0, 0, 1);
    camera.position.set(-30, -20, 26);
    this.camera = camera;

    const controls = new OrbitControls(camera, renderer.domElement);
    controls.enableDamping = true;
    controls.dampingFactor = 0.12;
    controls.maxPolarAngle = Math.PI * 0.495;
    controls.minDistance = 2;
    controls.maxDistance = 1500;
    this.controls = controls;

    scene.add(new THREE.HemisphereLight(0xdfe9ff, 0x303848, 1.9));
    const sun = new THREE.DirectionalLight(0xffffff, 1.4);
    sun.position.set(0.4, -0.6, 1.0);
    scene.add(sun);

    this.#makeGrid();
    this.#makePoints(maxPoints);
    this.#makeSurfaces(maxMeshVertices, maxMeshIndices);
    this.#makeOutlines(maxOutlineSegments);
    this.#makeSelection();
    this.#makeVehicle();
    this.#makeTrail(maxTrail);

    this.#bindInput();
    this.resize();
    new ResizeObserver(() => this.resize()).observe(container);
    this.lastFrame = performance.now();
    this.dirty = true;
    this.frames = 0;
    renderer.setAnimationLoop(() => this.#frame());
  }

  // ---------------------------------------------------------------- objects

  #makeGrid() {
    const grid = new THREE.GridHelper(600, 120, 0x2a3a52, 0x161e2b);
    grid.rotation.x = Math.PI / 2; // GridHelper lies in XZ; our ground is XY
    grid.material.transparent = true;
    grid.material.opacity = 0.55;
    grid.material.depthWrite = false;
    grid.renderOrder = -1;
    grid.position.z = -1.8;
    this.grid = grid;
    this.scene.add(grid);
  }

  #makePoints(max) {
    this.maxPoints = max;
    const geo = new THREE.BufferGeometry();
    const xyzi = new THREE.InterleavedBuffer(new Float32Array(max * 4), 4);
    xyzi.setUsage(THREE.DynamicDrawUsage);
    geo.setAttribute('position', new THREE.InterleavedBufferAttribute(xyzi, 3, 0));
    const col = new THREE.BufferAttribute(new Uint8Array(max * 3), 3, true);
    col.setUsage(THREE.DynamicDrawUsage);
    geo.setAttribute('color', col);
    geo.setDrawRange(0, 0);
    if (!this.pointsMaterial) {
      this.pointsMaterial = new THREE.PointsMaterial({ size: this.settings.pointSize, sizeAttenuation: false, vertexColors: true, fog: true });
    }
    const pts = new THREE.Points(geo, this.pointsMaterial);
    pts.frustumCulled = false;
    pts.matrixAutoUpdate = false;
    if (this.points) {
      this.scene.remove(this.points);
      this.points.geometry.dispose();
    }
    this.points = pts;
    this.scene.add(pts);
  }

  #makeSurfaces(maxV, maxI) {
    this.maxMeshVertices = maxV;
    this.maxMeshIndices = maxI;
    const geo = new THREE.BufferGeometry();
    const pos = new THREE.BufferAttribute(new Float32Array(maxV * 3), 3).setUsage(THREE.DynamicDrawUsage);
    const nrm = new THREE.BufferAttribute(new Float32Array(maxV * 3), 3).setUsage(THREE.DynamicDrawUsage);
    const col = new THREE.BufferAttribute(new Uint8Array(maxV * 3), 3, true).setUsage(THREE.DynamicDrawUsage);
    geo.setAttribute('position', pos);
    geo.setAttribute('normal', nrm);
    geo.setAttribute('color', col);
    geo.setIndex(new THREE.BufferAttribute(new Uint32Array(maxI), 1).setUsage(THREE.DynamicDrawUsage));
    geo.setDrawRange(0, 0);
    geo.boundingSphere = new THREE.Sphere(new THREE.Vector3(), 0);
    if (!this.surfaceMaterial) {
      this.surfaceMaterial = new THREE.MeshLambertMaterial({
        vertexColors: true,
        transparent: true,
        opacity: this.settings.surfaceOpacity,
        side: THREE.DoubleSide,
        depthWrite: false,
        polygonOffset: true,
        polygonOffsetFactor: 1,
        polygonOffsetUnits: 1,
      });
    }
    const mesh = new THREE.Mesh(geo, this.surfaceMaterial);
    mesh.frustumCulled = false;
    mesh.renderOrder = 1;
    if (this.surfaces) {
      this.scene.remove(this.surfaces);
      this.surfaces.geometry.dispose();
    }
    this.surfaces = mesh;
    this.scene.add(mesh);
  }

  /** Fat line segments (screen-space width) over instanced buffers we own and update in place. */
  #segments(maxSeg, material) {
    const geo = new LineSegmentsGeometry();
    const pos = new THREE.InstancedInterleavedBuffer(new Float32Array(maxSeg * 6), 6, 1).setUsage(THREE.DynamicDrawUsage);
    const col = new THREE.InstancedInterleavedBuffer(new Float32Array(maxSeg * 6), 6, 1).setUsage(THREE.DynamicDrawUsage);
    geo.setAttribute('instanceStart', new THREE.InterleavedBufferAttribute(pos, 3, 0));
    geo.setAttribute('instanceEnd', new THREE.InterleavedBufferAttribute(pos, 3, 3));
    geo.setAttribute('instanceColorStart', new THREE.InterleavedBufferAttribute(col, 3, 0));
    geo.setAttribute('instanceColorEnd', new THREE.InterleavedBufferAttribute(col, 3, 3));
    geo.instanceCount = 0;
    const lines = new LineSegments2(geo, material);
    lines.frustumCulled = false;
    return { lines, pos, col };
  }

  #makeOutlines(maxSeg) {
    this.maxOutlineSegments = maxSeg;
    if (!this.outlineMaterial) {
      this.outlineMaterial = new LineMaterial({ vertexColors: true, linewidth: 1.6, transparent: true, opacity: 0.95, fog: true });
    }
    const o = this.#segments(maxSeg, this.outlineMaterial);
    o.lines.renderOrder = 2;
    if (this.outlines) {
      this.scene.remove(this.outlines.lines);
      this.outlines.lines.geometry.dispose();
    }
    this.outlines = o;
    this.scene.add(o.lines);
  }

  #makeSelection() {
    const max = 4096;
    this.selectionMax = max;
    const mat = new LineMaterial({ color: 0xffffff, linewidth: 3.5, depthTest: false, transparent: true, opacity: 0.95 });
    const o = this.#segments(max, mat);
    o.col.array.fill(1);
    o.lines.renderOrder = 10;
    this.selection = o;
    this.scene.add(o.lines);
  }

  #makeVehicle() {
    // A car-sized box under the sensor (the sensor sits ~1.8 m above the road),
    // an arrow pointing forward (+x of the sensor frame) and the sensor puck.
    const car = new THREE.Group();
    const body = new THREE.Mesh(
      new THREE.BoxGeometry(4.4, 1.85, 1.3),
      new THREE.MeshLambertMaterial({ color: 0x2b3546, emissive: 0x0d1420 }),
    );
    body.position.set(-0.6, 0, -1.05);
    const cabin = new THREE.Mesh(
      new THREE.BoxGeometry(2.2, 1.6, 0.55),
      new THREE.MeshLambertMaterial({ color: 0x3a4a62, emissive: 0x0d1420 }),
    );
    cabin.position.set(-0.9, 0, -0.15);
    const edges = new THREE.LineSegments(
      new THREE.EdgesGeometry(body.geometry),
      new THREE.LineBasicMaterial({ color: 0x7fd4ff, transparent: true, opacity: 0.9 }),
    );
    edges.position.copy(body.position);
    const arrowShape = new THREE.Shape();
    arrowShape.moveTo(0, -1.1);
    arrowShape.lineTo(2.4, 0);
    arrowShape.lineTo(0, 1.1);
    arrowShape.lineTo(0.6, 0);
    arrowShape.closePath();
    const arrow = new THREE.Mesh(
      new THREE.ShapeGeometry(arrowShape),
      new THREE.MeshBasicMaterial({ color: 0x7fd4ff, side: THREE.DoubleSide, transparent: true, opacity: 0.95 }),
    );
    arrow.position.set(2.4, 0, -1.72);
    const puck = new THREE.Mesh(
      new THREE.CylinderGeometry(0.22, 0.22, 0.3, 20).rotateX(Math.PI / 2),
      new THREE.MeshLambertMaterial({ color: 0xe8eef7, emissive: 0x334455 }),
    );
    puck.position.set(0, 0, 0.05);
    car.add(body, cabin, edges, arrow, puck);
    car.matrixAutoUpdate = false;
    car.visible = false;
    this.vehicle = car;
    this.scene.add(car);
  }

  #makeTrail(max) {
    this.maxTrail = max;
    this.trailCount = 0;
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(new Float32Array(max * 3), 3).setUsage(THREE.DynamicDrawUsage));
    geo.setDrawRange(0, 0);
    const line = new THREE.Line(geo, new THREE.LineBasicMaterial({ color: 0x7fd4ff, transparent: true, opacity: 0.85 }));
    line.frustumCulled = false;
    line.renderOrder = 3;
    this.trail = line;
    this.scene.add(line);
  }

  // ---------------------------------------------------------------- updates

  /** Forget everything of the previous run (keeps the GPU buffers). */
  reset() {
    this.dirty = true;
    this.origin = null;
    this.polygonsById.clear();
    this.groundIds.clear();
    this.polygonIds = new Uint32Array(0);
    this.points.geometry.setDrawRange(0, 0);
    this.surfaces.geometry.setDrawRange(0, 0);
    this.outlines.lines.geometry.instanceCount = 0;
    this.trail.geometry.setDrawRange(0, 0);
    this.trailCount = 0;
    this.vehicle.visible = false;
    this.vehiclePose = null;
    this.groundZ = null;
    this.grid.position.z = -1.8;
    this.select(null);
    this.snapCamera = true;
  }

  /** Show one worker 'scan' message: points + labels + pose, and polygons / mesh when present. */
  showScan({ points, labels, pose, polygons, mesh }) {
    if (!this.origin) this.origin = [pose[12], pose[13], pose[14]];
    if (polygons) this.setPolygons(polygons); // first: the points' colours need the ground flags
    if (mesh) this.setMesh(mesh);
    this.setScan(points, labels, pose);
  }

  /** Local matrix of a world-from-sensor pose (column-major 16 numbers). */
  #localMatrix(pose, out) {
    const o = this.origin;
    out.fromArray(pose);
    out.elements[12] = pose[12] - o[0];
    out.elements[13] = pose[13] - o[1];
    out.elements[14] = pose[14] - o[2];
    return out;
  }

  /** The current scan: `points` stride 4 in the sensor frame, `labels` one per point. */
  setScan(points, labels, pose) {
    this.dirty = true;
    const n = points.length >> 2;
    if (n > this.maxPoints) this.#makePoints(nextPow2(n));
    const geo = this.points.geometry;
    const xyzi = geo.attributes.position.data;
    xyzi.array.set(points.subarray(0, n * 4));
    xyzi.clearUpdateRanges();
    xyzi.addUpdateRange(0, n * 4);
    xyzi.needsUpdate = true;
    const col = geo.attributes.color;
    colorPoints(labels, points, n, col.array, this.groundIds);
    col.clearUpdateRanges();
    col.addUpdateRange(0, n * 3);
    col.needsUpdate = true;
    geo.setDrawRange(0, n);
    this.#localMatrix(pose, this.points.matrix);
    this.points.matrixWorldNeedsUpdate = true;

    // Vehicle and trail.
    this.vehiclePose = pose;
    this.#localMatrix(pose, this.vehicle.matrix);
    this.vehicle.matrixWorldNeedsUpdate = true;
    this.vehicle.visible = true;
    const tp = this.trail.geometry.attributes.position;
    if (this.trailCount >= this.maxTrail) {
      tp.array.copyWithin(0, 3 * (this.maxTrail >> 1));
      this.trailCount = this.maxTrail - (this.maxTrail >> 1);
    }
    const k = this.trailCount++;
    tp.array[k * 3] = pose[12] - this.origin[0];
    tp.array[k * 3 + 1] = pose[13] - this.origin[1];
    tp.array[k * 3 + 2] = pose[14] - this.origin[2] - 1.75; // on the road, under the sensor
    tp.needsUpdate = true;
    this.trail.geometry.setDrawRange(0, this.trailCount);
  }

  /** Outlines (and the pick table) from Scenario.polygons(). */
  setPolygons(polygons) {
    this.dirty = true;
    this.polygonsById.clear();
    this.groundIds.clear();
    let ns = 0;
    for (const p of polygons) {
      this.polygonsById.set(p.id, p);
      if (p.ground) this.groundIds.add(p.id);
      ns += p.vertices.length / 3;
    }
    if (ns > this.maxOutlineSegments) this.#makeOutlines(nextPow2(ns));
    const { lines, pos: pbuf, col: cbuf } = this.outlines;
    const pos = pbuf.array;
    const col = cbuf.array;
    const [ox, oy, oz] = this.origin || [0, 0, 0];
    let k = 0; // segments
    let ground = null;
    for (const p of polygons) {
      const v = p.vertices;
      const m = v.length / 3;
      const c = idColor(p.id, p.ground);
      const r = Math.min(1, c[0] * 1.12);
      const g = Math.min(1, c[1] * 1.12);
      const b = Math.min(1, c[2] * 1.12);
      for (let i = 0; i < m; i++) {
        const j = (i + 1) % m;
        const o = k * 6;
        pos[o] = v[i * 3] - ox;
        pos[o + 1] = v[i * 3 + 1] - oy;
        pos[o + 2] = v[i * 3 + 2] - oz;
        pos[o + 3] = v[j * 3] - ox;
        pos[o + 4] = v[j * 3 + 1] - oy;
        pos[o + 5] = v[j * 3 + 2] - oz;
        col[o] = col[o + 3] = r;
        col[o + 1] = col[o + 4] = g;
        col[o + 2] = col[o + 5] = b;
        k++;
      }
      if (p.ground && (!ground || p.area > ground.area)) ground = p;
    }
    for (const buf of [pbuf, cbuf]) {
      buf.clearUpdateRanges();
      buf.addUpdateRange(0, k * 6);
      buf.needsUpdate = true;
    }
    lines.geometry.instanceCount = k;

    // The grid sits just under the largest ground polygon.
    if (ground && Math.abs(ground.normal[2]) > 0.9) {
      let z = 0;
      const m = ground.vertices.length / 3;
      for (let i = 0; i < m; i++) z += ground.vertices[i * 3 + 2];
      this.groundZ = z / m - oz;
      this.grid.position.z = this.groundZ - 0.05;
    }
    if (this.selectedId !== null) this.select(this.polygonsById.has(this.selectedId) ? this.selectedId : null);
  }

  /** Filled surfaces from Scenario.mesh() (positions relative to mesh.origin). */
  setMesh({ positions, indices, polygonIds, origin }) {
    this.dirty = true;
    const nv = positions.length / 3;
    const ni = indices.length;
    if (nv > this.maxMeshVertices || ni > this.maxMeshIndices) {
      this.#makeSurfaces(Math.max(this.maxMeshVertices, nextPow2(nv)), Math.max(this.maxMeshIndices, nextPow2(ni)));
    }
    const geo = this.surfaces.geometry;
    const pos = geo.attributes.position;
    const nrm = geo.attributes.normal;
    const col = geo.attributes.color;
    pos.array.set(positions);
    geo.index.array.set(indices);
    const up = [0, 0, 1];
    for (let t = 0; t < ni / 3; t++) {
      const id = polygonIds[t];
      const p = this.polygonsById.get(id);
      const c = idColor(id, p ? p.ground : false);
      const n = p ? p.normal : up;
      for (let s = 0; s < 3; s++) {
        const v = indices[t * 3 + s];
        col.array[v * 3] = c[0] * 255;
        col.array[v * 3 + 1] = c[1] * 255;
        col.array[v * 3 + 2] = c[2] * 255;
        nrm.array[v * 3] = n[0];
        nrm.array[v * 3 + 1] = n[1];
        nrm.array[v * 3 + 2] = n[2];
      }
    }
    for (const a of [pos, nrm, col]) {
      a.clearUpdateRanges();
      a.addUpdateRange(0, nv * 3);
      a.needsUpdate = true;
    }
    geo.index.clearUpdateRanges();
    geo.index.addUpdateRange(0, ni);
    geo.index.needsUpdate = true;
    geo.setDrawRange(0, ni);
    this.polygonIds = polygonIds;
    // The mesh's own origin, placed in the local frame (f64 difference).
    const o = this.origin || origin;
    this.surfaces.position.set(origin[0] - o[0], origin[1] - o[1], origin[2] - o[2]);
    // Bounding sphere of the valid vertices only (raycasting tests it first).
    const bs = geo.boundingSphere;
    const box = new THREE.Box3();
    const v = new THREE.Vector3();
    for (let i = 0; i < nv; i++) box.expandByPoint(v.fromArray(positions, i * 3));
    if (nv > 0) {
      box.getCenter(bs.center);
      bs.radius = box.getSize(v).length() / 2 + 1e-3;
    } else {
      bs.radius = -1;
    }
  }

  // ---------------------------------------------------------------- picking

  /** The polygon under a client (CSS pixel) position, or null. */
  pickAt(clientX, clientY) {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    const ray = new THREE.Raycaster();
    ray.setFromCamera(ndc, this.camera);
    if (!this.surfaces.visible && !this.settings.showSurfaces) this.surfaces.visible = true;
    this.surfaces.updateMatrixWorld();
    const hits = ray.intersectObject(this.surfaces, false);
    this.surfaces.visible = this.settings.showSurfaces;
    for (const h of hits) {
      const id = this.polygonIds[h.faceIndex];
      const p = this.polygonsById.get(id);
      if (p) return p;
    }
    return null;
  }

  /** Highlight a polygon's outline (null clears). */
  select(id) {
    this.dirty = true;
    this.selectedId = id;
    const { lines, pos: buf } = this.selection;
    const p = id === null ? null : this.polygonsById.get(id);
    if (!p) {
      lines.geometry.instanceCount = 0;
      return;
    }
    const o = this.origin || [0, 0, 0];
    const v = p.vertices;
    const m = Math.min(v.length / 3, this.selectionMax);
    const a = buf.array;
    for (let i = 0; i < m; i++) {
      const j = (i + 1) % m;
      for (let d = 0; d < 3; d++) {
        a[i * 6 + d] = v[i * 3 + d] - o[d];
        a[i * 6 + 3 + d] = v[j * 3 + d] - o[d];
      }
    }
    buf.clearUpdateRanges();
    buf.addUpdateRange(0, m * 6);
    buf.needsUpdate = true;
    lines.geometry.instanceCount = m;
  }

  // ---------------------------------------------------------------- camera & input

  setFollow(on) {
    this.settings.follow = on;
    this.dispatchEvent(new CustomEvent('follow', { detail: on }));
  }

  #bindInput() {
    const el = this.renderer.domElement;
    let down = null;
    el.addEventListener('pointerdown', (e) => {
      down = { x: e.clientX, y: e.clientY, moved: false };
    });
    el.addEventListener('pointermove', (e) => {
      if (!down || !e.buttons) return;
      if (Math.hypot(e.clientX - down.x, e.clientY - down.y) > 3) {
        down.moved = true;
        if (this.settings.follow) this.setFollow(false); // the user takes over
      }
    });
    el.addEventListener('pointerup', (e) => {
      if (down && !down.moved && e.button === 0) {
        const p = this.pickAt(e.clientX, e.clientY);
        this.select(p ? p.id : null);
        this.dispatchEvent(new CustomEvent('pick', { detail: p }));
      }
      down = null;
    });
    el.addEventListener('wheel', () => this.settings.follow && this.setFollow(false), { passive: true });
  }

  #followCamera(dt) {
    const pose = this.vehiclePose;
    if (!pose || !this.origin) return false;
    const e = pose;
    const vx = e[12] - this.origin[0];
    const vy = e[13] - this.origin[1];
    const vz = e[14] - this.origin[2];
    const yaw = Math.atan2(e[1], e[0]);
    const c = Math.cos(yaw);
    const s = Math.sin(yaw);
    // Chase view: behind, to the left and above the vehicle, looking ahead.
    const ahead = 10;
    const off = [-34, -20, 30];
    const tx = vx + c * ahead;
    const ty = vy + s * ahead;
    const tz = vz - 1.8;
    const px = vx + c * off[0] - s * off[1];
    const py = vy + s * off[0] + c * off[1];
    const pz = vz + off[2];
    // Smoothly, except in software GL where every frame counts.
    const k = this.snapCamera || this.software ? 1 : 1 - Math.exp(-dt * 2.5);
    this.snapCamera = false;
    const t = this.controls.target;
    const c2 = this.camera.position;
    const moved = Math.max(Math.abs(tx - t.x), Math.abs(ty - t.y), Math.abs(tz - t.z), Math.abs(px - c2.x), Math.abs(py - c2.y), Math.abs(pz - c2.z));
    if (moved < 1e-3) return false;
    t.x += (tx - t.x) * k;
    t.y += (ty - t.y) * k;
    t.z += (tz - t.z) * k;
    c2.x += (px - c2.x) * k;
    c2.y += (py - c2.y) * k;
    c2.z += (pz - c2.z) * k;
    return true;
  }

  resize() {
    this.dirty = true;
    const w = this.container.clientWidth || 1;
    const h = this.container.clientHeight || 1;
    this.renderer.setSize(w, h, false);
    this.renderer.domElement.style.width = '100%';
    this.renderer.domElement.style.height = '100%';
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    // Fat lines: widths in CSS pixels.
    this.outlineMaterial?.resolution.set(w, h);
    this.selection?.lines.material.resolution.set(w, h);
  }

  /** Ask for a new frame (the view renders only when something changed). */
  invalidate() {
    this.dirty = true;
  }

  #frame() {
    const now = performance.now();
    const dt = Math.min((now - this.lastFrame) / 1000, 0.1);
    this.lastFrame = now;
    let dirty = this.dirty;
    if (this.settings.follow && this.#followCamera(dt)) dirty = true;
    if (this.controls.update()) dirty = true;
    const s = this.settings;
    const sig = `${s.pointSize}|${s.showPoints}|${s.showSurfaces}|${s.showOutlines}|${s.surfaceOpacity}`;
    if (sig !== this.lastSettings) {
      this.lastSettings = sig;
      this.pointsMaterial.size = s.pointSize;
      this.points.visible = s.showPoints;
      this.surfaces.visible = s.showSurfaces;
      this.outlines.lines.visible = s.showOutlines;
      this.surfaceMaterial.opacity = s.surfaceOpacity;
      dirty = true;
    }
    if (!dirty) return;
    this.dirty = false;
    // Fog starts a little beyond what the camera looks at, wherever it is.
    const d = this.camera.position.distanceTo(this.controls.target);
    this.scene.fog.near = d + 110;
    this.scene.fog.far = d + 420;
    this.renderer.render(this.scene, this.camera);
    this.frames++;
  }

  /** Stop rendering and free GPU memory. */
  dispose() {
    this.renderer.setAnimationLoop(null);
    this.scene.traverse((o) => {
      o.geometry?.dispose();
      o.material?.dispose?.();
    });
    this.renderer.dispose();
    this.renderer.domElement.remove();
  }
}
