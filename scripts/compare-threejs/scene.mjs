// Writes the comparison's scene as a glTF binary: a 100 m ground, 100 boxes of 1 m on a
// 10 x 10 grid, `lights` KHR_lights_punctual point lights of range 6 scattered 0.5 to 3 m
// above the ground (a fixed seed), and a camera looking over it: a scene written the way one
// writes one for an engine. Usage: node scene.mjs LIGHTS OUT.glb
import { writeFileSync } from "node:fs";

const [lights, out] = [Number(process.argv[2]), process.argv[3]];
let seed = 12345;
const random = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648);

// One unit box (24 vertices, normals per face) and one ground quad, as glTF accessors.
const positions = [], normals = [], indices = [];
const face = (n, u, v) => {
  const base = positions.length / 3;
  for (const [a, b] of [[-1, -1], [1, -1], [1, 1], [-1, 1]]) {
    for (let k = 0; k < 3; k++) positions.push(0.5 * (n[k] + a * u[k] + b * v[k]));
    normals.push(...n);
  }
  indices.push(base, base + 1, base + 2, base, base + 2, base + 3);
};
face([1, 0, 0], [0, 0, -1], [0, 1, 0]); face([-1, 0, 0], [0, 0, 1], [0, 1, 0]);
face([0, 1, 0], [1, 0, 0], [0, 0, -1]); face([0, -1, 0], [1, 0, 0], [0, 0, 1]);
face([0, 0, 1], [1, 0, 0], [0, 1, 0]); face([0, 0, -1], [-1, 0, 0], [0, 1, 0]);
const boxVertices = positions.length / 3, boxIndices = indices.length;
const g = positions.length / 3;
for (const [x, z] of [[-50, 50], [50, 50], [50, -50], [-50, -50]]) { positions.push(x, 0, z); normals.push(0, 1, 0); }
indices.push(0, 1, 2, 0, 2, 3);

const f32 = new Float32Array([...positions, ...normals]);
const u16 = new Uint16Array(indices);
const pad = (n) => (n + 3) & ~3;
const bin = Buffer.alloc(pad(f32.byteLength) + pad(u16.byteLength));
Buffer.from(f32.buffer).copy(bin, 0);
Buffer.from(u16.buffer).copy(bin, pad(f32.byteLength));
const vBytes = positions.length * 4;
const box = (min, max) => ({ min, max });
const gltf = {
  asset: { version: "2.0", generator: "lightgrid scripts/compare-threejs" },
  extensionsUsed: ["KHR_lights_punctual"],
  buffers: [{ byteLength: bin.length }],
  bufferViews: [
    { buffer: 0, byteOffset: 0, byteLength: vBytes, target: 34962 },
    { buffer: 0, byteOffset: vBytes, byteLength: vBytes, target: 34962 },
    { buffer: 0, byteOffset: pad(f32.byteLength), byteLength: u16.byteLength, target: 34963 },
  ],
  accessors: [
    { bufferView: 0, componentType: 5126, count: boxVertices, type: "VEC3", ...box([-0.5, -0.5, -0.5], [0.5, 0.5, 0.5]) },
    { bufferView: 1, componentType: 5126, count: boxVertices, type: "VEC3" },
    { bufferView: 2, componentType: 5123, count: boxIndices, type: "SCALAR" },
    { bufferView: 0, byteOffset: boxVertices * 12, componentType: 5126, count: 4, type: "VEC3", ...box([-50, 0, -50], [50, 0, 50]) },
    { bufferView: 1, byteOffset: boxVertices * 12, componentType: 5126, count: 4, type: "VEC3" },
    { bufferView: 2, byteOffset: boxIndices * 2, componentType: 5123, count: 6, type: "SCALAR" },
  ],
  materials: [
    { name: "ground", pbrMetallicRoughness: { baseColorFactor: [0.8, 0.8, 0.8, 1], metallicFactor: 0, roughnessFactor: 0.6 } },
    { name: "box", pbrMetallicRoughness: { baseColorFactor: [0.7, 0.5, 0.4, 1], metallicFactor: 0, roughnessFactor: 0.5 } },
  ],
  meshes: [
    { name: "box", primitives: [{ attributes: { POSITION: 0, NORMAL: 1 }, indices: 2, material: 1 }] },
    { name: "ground", primitives: [{ attributes: { POSITION: 3, NORMAL: 4 }, indices: 5, material: 0 }] },
  ],
  cameras: [{ type: "perspective", perspective: { yfov: 0.9, znear: 0.1, zfar: 200, aspectRatio: 16 / 9 } }],
  extensions: { KHR_lights_punctual: { lights: [] } },
  nodes: [],
  scenes: [{ nodes: [] }],
  scene: 0,
};
const node = (n) => { gltf.nodes.push(n); gltf.scenes[0].nodes.push(gltf.nodes.length - 1); };
node({ name: "ground", mesh: 1 });
for (let i = 0; i < 100; i++) {
  node({ name: `box${i}`, mesh: 0, translation: [(i % 10) * 8 - 36, 0.5, Math.floor(i / 10) * 8 - 36] });
}
// The camera 30 m up at one side, looking down at the middle (a quaternion about x).
const pitch = -0.55;
node({ name: "camera", camera: 0, translation: [0, 30, 55], rotation: [Math.sin(pitch / 2), 0, 0, Math.cos(pitch / 2)] });
for (let i = 0; i < lights; i++) {
  const hue = random();
  gltf.extensions.KHR_lights_punctual.lights.push({
    type: "point", range: 6, intensity: 20,
    color: [0.5 + 0.5 * Math.cos(6.283 * hue), 0.5 + 0.5 * Math.cos(6.283 * (hue + 0.33)), 0.5 + 0.5 * Math.cos(6.283 * (hue + 0.67))],
  });
  node({ name: `light${i}`, translation: [random() * 90 - 45, 0.5 + random() * 2.5, random() * 90 - 45], extensions: { KHR_lights_punctual: { light: i } } });
}
const json = Buffer.from(JSON.stringify(gltf));
const jsonPadded = Buffer.concat([json, Buffer.alloc(pad(json.length) - json.length, 0x20)]);
const header = Buffer.alloc(12), jh = Buffer.alloc(8), bh = Buffer.alloc(8);
header.writeUInt32LE(0x46546c67, 0); header.writeUInt32LE(2, 4);
header.writeUInt32LE(12 + 8 + jsonPadded.length + 8 + bin.length, 8);
jh.writeUInt32LE(jsonPadded.length, 0); jh.writeUInt32LE(0x4e4f534a, 4);
bh.writeUInt32LE(bin.length, 0); bh.writeUInt32LE(0x004e4942, 4);
writeFileSync(out, Buffer.concat([header, jh, jsonPadded, bh, bin]));
