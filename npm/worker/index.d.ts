// Types of polyscene/worker (PolysceneClient, client.js; the protocol is in worker.js).
import type { DetectOptions, Polygon, PipelineOptions, ScanReport, Mesh } from "../web/polyscene.js";

/** Where a run's scans come from. */
export type ScanSource =
  | { kind: "sim"; layout: "street" | "crossing"; seed: number; label?: string }
  | {
      kind: "files";
      label: string;
      /** points: stride 4, sensor frame; pose: 16 numbers column-major world-from-sensor, or null for identity. */
      scans: { name: string; points: Float32Array; pose: ArrayLike<number> | null }[];
    };

/** The worker's 'ready' message: every option of each preset. */
export interface ReadyMessage {
  type: "ready";
  defaults: { gpp1: Required<Omit<PipelineOptions, "preset">>; gpp2: Required<Omit<PipelineOptions, "preset">> };
}

/** One processed scan of a run. */
export interface ScanMessage {
  type: "scan";
  run: number;
  index: number;
  total: number;
  name: string;
  points: Float32Array;
  labels: Uint32Array;
  pose: Float64Array;
  report: ScanReport;
  /** Only when the scan changed the map. */
  polygons?: Polygon[];
  mesh?: Mesh;
  workerMs: number;
}

export interface ResetMessage {
  type: "reset";
  run: number;
  source: { kind: "sim" | "files"; label: string; total: number };
}

export interface StateMessage {
  type: "state";
  run: number;
  playing: boolean;
  done: boolean;
}

/** fatal: the module is unusable; the client starts a new worker (at most 3 times). */
export interface ErrorMessage {
  type: "error";
  run: number;
  message: string;
  fatal: boolean;
}

/** The worker began a `detect` call ('started'), or finished a round of its cascade ('round': the first, then at most one per 50 ms). */
export interface ProgressMessage {
  type: "progress";
  request: number;
  stage: "started" | "round";
  /** Points of the cloud. */
  points: number;
  /** 'round' only: rounds done, points not yet explained or discarded (falls towards 0), polygons so far. */
  round?: number;
  pointsLeft?: number;
  polygons?: number;
}

export interface PolysceneClientEventMap {
  ready: CustomEvent<ReadyMessage>;
  reset: CustomEvent<ResetMessage>;
  scan: CustomEvent<ScanMessage>;
  state: CustomEvent<StateMessage>;
  error: CustomEvent<ErrorMessage>;
  progress: CustomEvent<ProgressMessage>;
}

export class PolysceneClient extends EventTarget {
  /** workerUrl: the worker module (default: worker.js next to client.js; give it when bundling with esbuild). */
  constructor(options?: { workerUrl?: string | URL });
  /** Resolves once the worker's wasm is loaded; rejects when it cannot load. Calls made earlier wait, in order. */
  ready: Promise<ReadyMessage>;
  worker: Worker;
  run: number;
  /** Start a new run over `source` (omitted: the previous one) with new Scenario(options). Returns the run number. */
  configure(options: PipelineOptions, source?: ScanSource, flags?: { play?: boolean }): number;
  play(): void;
  pause(): void;
  step(): void;
  /** Scans per second; 0 for as fast as possible. */
  setSpeed(scansPerSecond: number): void;
  /** The run's snapshot string (Scenario.toJSONString()), or null before a run. */
  snapshot(): Promise<string | null>;
  /** One-shot detect in the worker; `signal` aborts it (the promise rejects with `signal.reason`). */
  detect(
    points: Float32Array,
    options?: DetectOptions,
    call?: { signal?: AbortSignal; onProgress?: (progress: ProgressMessage) => void },
  ): Promise<Polygon[]>;
  terminate(): void;
  addEventListener<K extends keyof PolysceneClientEventMap>(
    type: K,
    listener: (this: PolysceneClient, ev: PolysceneClientEventMap[K]) => unknown,
    options?: boolean | AddEventListenerOptions,
  ): void;
  addEventListener(type: string, listener: EventListenerOrEventListenerObject | null, options?: boolean | AddEventListenerOptions): void;
  removeEventListener<K extends keyof PolysceneClientEventMap>(
    type: K,
    listener: (this: PolysceneClient, ev: PolysceneClientEventMap[K]) => unknown,
    options?: boolean | EventListenerOptions,
  ): void;
  removeEventListener(type: string, listener: EventListenerOrEventListenerObject | null, options?: boolean | EventListenerOptions): void;
}
