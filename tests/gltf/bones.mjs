// Checks that a .glb's animation moves the skeleton: rib nodes have translation and rotation channels (the
// fixed ones, such as floating ribs a model holds still, have none), and at the deepest inspiration (largest summed morph weight) the ribs are posed differently from half a breath
// earlier: their anterior ends (the node's mesh vertex farthest from its rest centre, posed by the node's TRS)
// move, in the mean over the ribs, by more than 1 mm. Each node named after HALF_BREATH_S (a shoulder girdle's
// scapulae, say) must be animated and rise (+Y) by at least 3 mm over the same half breath.
// Usage: node bones.mjs FILE.glb HALF_BREATH_S [RISING_NODE...]
import fs from 'node:fs';

const [file, halfBreath, ...rising] = process.argv.slice(2);
if (!file || !halfBreath) {
  console.error('usage: node bones.mjs FILE.glb HALF_BREATH_S [RISING_NODE...]');
  process.exit(2);
}

// the GLB container: a JSON chunk, then a BIN chunk (glTF 2.0 spec, "Binary glTF Layout")
const bytes = fs.readFileSync(file);
const jsonLength = bytes.readUInt32LE(12);
const gltf = JSON.parse(bytes.subarray(20, 20 + jsonLength).toString('utf8'));
const binStart = 20 + jsonLength + 8;
const floats = (index) => {
  const a = gltf.accessors[index];
  const v = gltf.bufferViews[a.bufferView];
  const n = { SCALAR: 1, VEC3: 3, VEC4: 4 }[a.type];
  const start = binStart + (v.byteOffset ?? 0) + (a.byteOffset ?? 0);
  const out = new Float32Array(a.count * n);
  for (let i = 0; i < out.length; ++i) out[i] = bytes.readFloatLE(start + 4 * i);
  return { values: out, n };
};

// linear interpolation of a sampler's output at time t (quaternions normalised after the blend)
const sample = (sampler, t) => {
  const times = floats(sampler.input).values;
  const { values, n } = floats(sampler.output);
  let f = 0;
  while (f + 2 < times.length && times[f + 1] <= t) ++f;
  const u = Math.min(1, Math.max(0, (t - times[f]) / (times[f + 1] - times[f])));
  const x = Array.from({ length: n }, (_, i) => (1 - u) * values[f * n + i] + u * values[(f + 1) * n + i]);
  if (n === 4) {
    const len = Math.hypot(...x);
    return x.map((c) => c / len);
  }
  return x;
};
const rotate = ([qx, qy, qz, qw], [x, y, z]) => {
  // v + 2 w (q x v) + 2 q x (q x v)
  const cx = qy * z - qz * y, cy = qz * x - qx * z, cz = qx * y - qy * x;
  return [x + 2 * (qw * cx + qy * cz - qz * cy), y + 2 * (qw * cy + qz * cx - qx * cz),
          z + 2 * (qw * cz + qx * cy - qy * cx)];
};

const animation = gltf.animations?.[0];
if (!animation) {
  console.error(`FAIL ${file}: no animation`);
  process.exit(1);
}
const weights = animation.channels.find((c) => c.target.path === 'weights');
const wTimes = floats(animation.samplers[weights.sampler].input).values;
const w = floats(animation.samplers[weights.sampler].output).values;
const k = w.length / wTimes.length;
let peak = 0, best = -Infinity;
for (let f = 0; f < wTimes.length; ++f) {
  let s = 0;
  for (let j = 0; j < k; ++j) s += w[f * k + j];
  if (s > best) best = s, peak = wTimes[f];
}
const t1 = peak, t0 = peak - Number(halfBreath) >= 0 ? peak - Number(halfBreath) : peak + Number(halfBreath);

const failures = [];
let ribs = 0, still = 0, moved = 0, sum = 0;
gltf.nodes.forEach((node, index) => {
  if (!node.name.startsWith('rib')) return;
  const channel = (path) => animation.channels.find((c) => c.target.node === index && c.target.path === path);
  const tr = channel('translation'), rot = channel('rotation');
  if (!tr && !rot) {
    ++still;
    return;
  }
  if (!tr || !rot) {
    failures.push(`${node.name}: a rotation without a translation channel or the reverse`);
    return;
  }
  ++ribs;
  // the anterior end: the mesh vertex farthest from the node's origin (its rest centre of mass)
  const positions = floats(gltf.meshes[node.mesh].primitives[0].attributes.POSITION).values;
  let tip = [0, 0, 0], reach = -1;
  for (let i = 0; i < positions.length; i += 3) {
    const d = Math.hypot(positions[i], positions[i + 1], positions[i + 2]);
    if (d > reach) reach = d, tip = [positions[i], positions[i + 1], positions[i + 2]];
  }
  const pose = (t) => {
    const p = rotate(sample(animation.samplers[rot.sampler], t), tip);
    const x = sample(animation.samplers[tr.sampler], t);
    return [p[0] + x[0], p[1] + x[1], p[2] + x[2]];
  };
  const a = pose(t0), b = pose(t1);
  const d = Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  sum += d;
  if (d > 1e-4) ++moved;
});
const mean = ribs > 0 ? sum / ribs : 0;
console.log(`${file}: ${ribs} animated rib nodes (${still} still), frames at ${t0.toFixed(2)} s and ${t1.toFixed(2)} s (peak inspiration):` +
            ` the rib tips move ${(1e3 * mean).toFixed(2)} mm on average, ${moved} ribs by more than 0.1 mm`);
if (ribs < 2) failures.push(`only ${ribs} animated rib nodes`);
if (mean < 1e-3) failures.push(`rib tips move ${(1e3 * mean).toFixed(2)} mm on average half a breath apart (< 1 mm)`);
for (const name of rising) {
  const index = gltf.nodes.findIndex((node) => node.name === name);
  const tr = animation.channels.find((c) => c.target.node === index && c.target.path === 'translation');
  if (index < 0 || !tr) {
    failures.push(`${name}: ${index < 0 ? 'no such node' : 'no translation channel'}`);
    continue;
  }
  const rise = sample(animation.samplers[tr.sampler], t1)[1] - sample(animation.samplers[tr.sampler], t0)[1];
  console.log(`${file}: ${name} rises ${(1e3 * rise).toFixed(2)} mm`);
  if (rise < 3e-3) failures.push(`${name} rises ${(1e3 * rise).toFixed(2)} mm half a breath apart (< 3 mm)`);
}
for (const f of failures) console.error(`FAIL ${f}`);
process.exit(failures.length === 0 ? 0 : 1);
