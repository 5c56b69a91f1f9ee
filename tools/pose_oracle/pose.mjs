#!/usr/bin/env node
// Independent pose oracle: world-space triangle corners of a glTF scene, posed by three.js.
//
//   node tools/pose_oracle/pose.mjs FILE.gltf|FILE.glb [--animation NAME|INDEX] [--time SECONDS]
//                                   [--digits N] [--check-skin]
//
// Prints {"meshes": [{"node", "mesh", "primitive", "triangles": [[[x,y,z]x3], ...]}, ...],
//         "camera": {"node", "camera", "position", "forward", "up"} | null}
// to stdout. See README.md beside this file for the exact semantics and limits.

import fs from 'node:fs';
import path from 'node:path';
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

function usage(msg) {
	if (msg) process.stderr.write(`pose.mjs: ${msg}\n`);
	process.stderr.write(
		'usage: node pose.mjs FILE.gltf|FILE.glb [--animation NAME|INDEX] [--time SECONDS] [--digits N] [--check-skin] [--normalize-rotations]\n'
	);
	process.exit(2);
}

// ---- arguments --------------------------------------------------------------------------
const args = process.argv.slice(2);
let file = null;
let animationArg = null;
let timeArg = null;
let digits = 7;
let checkSkin = false;
let normalizeRotations = false;
for (let i = 0; i < args.length; i++) {
	const a = args[i];
	if (a === '--animation') animationArg = args[++i];
	else if (a === '--time') timeArg = args[++i];
	else if (a === '--digits') digits = parseInt(args[++i], 10);
	else if (a === '--check-skin') checkSkin = true;
	else if (a === '--normalize-rotations') normalizeRotations = true;
	else if (a === '-h' || a === '--help') usage();
	else if (a.startsWith('--')) usage(`unknown option ${a}`);
	else if (file === null) file = a;
	else usage(`unexpected argument ${a}`);
}
if (file === null) usage('no file given');
if (animationArg === undefined || timeArg === undefined) usage('option needs a value');
if (timeArg !== null && animationArg === null) usage('--time needs --animation');
const time = timeArg === null ? 0 : Number(timeArg);
if (!Number.isFinite(time)) usage(`bad --time ${timeArg}`);
if (!(digits >= 1 && digits <= 17)) usage('bad --digits');

// ---- read the file and its buffers with fs (no DOM, no fetch) ----------------------------
const dir = path.dirname(path.resolve(file));
const raw = fs.readFileSync(file);
let json;
let glbBody = null;
if (raw.length >= 12 && raw.toString('latin1', 0, 4) === 'glTF') {
	// GLB container: JSON chunk, then an optional BIN chunk.
	const total = raw.readUInt32LE(8);
	let off = 12;
	while (off + 8 <= total) {
		const len = raw.readUInt32LE(off);
		const type = raw.readUInt32LE(off + 4);
		const chunk = raw.subarray(off + 8, off + 8 + len);
		if (type === 0x4e4f534a) json = JSON.parse(chunk.toString('utf8'));
		else if (type === 0x004e4942 && glbBody === null) glbBody = chunk;
		off += 8 + len;
	}
	if (!json) throw new Error('GLB without a JSON chunk');
} else {
	json = JSON.parse(raw.toString('utf8'));
}

function toArrayBuffer(buf) {
	return buf.buffer.slice(buf.byteOffset, buf.byteOffset + buf.byteLength);
}

const buffers = (json.buffers || []).map((b, i) => {
	if (b.uri === undefined) {
		if (i === 0 && glbBody !== null) return toArrayBuffer(glbBody);
		throw new Error(`buffer ${i} has no uri and there is no GLB body`);
	}
	const m = /^data:[^,]*?(;base64)?,(.*)$/s.exec(b.uri);
	if (m) {
		return toArrayBuffer(m[1] ? Buffer.from(m[2], 'base64') : Buffer.from(decodeURIComponent(m[2]), 'latin1'));
	}
	return toArrayBuffer(fs.readFileSync(path.join(dir, decodeURIComponent(b.uri))));
});

// Images and textures are irrelevant to positions: drop them, and replace every material by an
// empty one (same count, so primitives' material indices stay valid). Nothing geometric reads a
// material in GLTFLoader.
delete json.images;
delete json.textures;
delete json.samplers;
if (json.materials) json.materials = json.materials.map((m) => (m && m.name ? { name: m.name } : {}));
for (const key of ['extensionsUsed', 'extensionsRequired']) {
	if (json[key]) json[key] = json[key].filter((e) => !e.startsWith('KHR_materials_') && e !== 'KHR_texture_transform' && e !== 'KHR_texture_basisu' && e !== 'EXT_texture_webp' && e !== 'EXT_texture_avif');
}

// ---- parse ---------------------------------------------------------------------------------
const loader = new GLTFLoader();
let parserRef = null;
loader.register((parser) => {
	parserRef = parser;
	// Buffers come from fs, never through FileLoader/fetch.
	parser.loadBuffer = (index) => Promise.resolve(buffers[index]);
	return { name: 'pose_oracle_fs' };
});

// Silence three's console chatter on stdout (warnings go to stderr).
const origLog = console.log;
console.log = (...a) => process.stderr.write(a.join(' ') + '\n');
console.warn = (...a) => process.stderr.write('warning: ' + a.join(' ') + '\n');

const gltf = await new Promise((resolve, reject) => {
	loader.parse(JSON.stringify(json), dir + path.sep, resolve, reject);
});
const parser = gltf.parser || parserRef;
const root = gltf.scene;
if (!root) throw new Error('the file has no scene');
const sceneIndex = json.scene !== undefined ? json.scene : 0;

// three uses rotations as given: a node rotation or a STEP / LINEAR rotation key that is not
// of unit length scales and shears the node a little (the matrix formula assumes |q| = 1), and
// LINEAR between two equal keys returns the key as is, between unequal ones slerps the
// non-unit keys. glTF requires unit quaternions; with --normalize-rotations every node rotation
// and every STEP / LINEAR rotation key is normalised first (CUBICSPLINE results are normalised
// by three anyway).
if (normalizeRotations) {
	root.traverse((o) => o.quaternion.normalize());
	for (const c of gltf.animations) {
		for (const t of c.tracks) {
			if (!(t instanceof THREE.QuaternionKeyframeTrack)) continue;
			if (t.createInterpolant && t.createInterpolant.isInterpolantFactoryMethodGLTFCubicSpline) continue;
			const v = t.values;
			for (let i = 0; i + 3 < v.length; i += 4) {
				const n = Math.hypot(v[i], v[i + 1], v[i + 2], v[i + 3]);
				if (n > 0) for (let k = 0; k < 4; k++) v[i + k] /= n;
			}
		}
	}
}

// ---- animation -------------------------------------------------------------------------------
let clip = null;
if (animationArg !== null) {
	const anims = json.animations || [];
	let index = -1;
	if (/^\d+$/.test(animationArg)) index = parseInt(animationArg, 10);
	else index = anims.findIndex((a) => a.name === animationArg);
	if (index < 0 || index >= gltf.animations.length) {
		process.stderr.write(
			`pose.mjs: no animation ${JSON.stringify(animationArg)}; the file has: ` +
				anims.map((a, i) => `${i}:${JSON.stringify(a.name ?? '')}`).join(', ') + '\n'
		);
		process.exit(2);
	}
	clip = gltf.animations[index];
	const mixer = new THREE.AnimationMixer(root);
	const action = mixer.clipAction(clip);
	// glTF: hold the first value before the first key and the last after the last key.
	action.setLoop(THREE.LoopOnce, 1);
	action.clampWhenFinished = true;
	action.play();
	mixer.setTime(time); // evaluates the clip at clamp(time, 0, clip.duration)
}

root.updateMatrixWorld(true);

// ---- map glTF nodes to three objects -----------------------------------------------------------
function inRoot(obj) {
	for (let o = obj; o; o = o.parent) if (o === root) return true;
	return false;
}
const nodeObject = new Map();
const nodeObjectSet = new Set();
const nodes = json.nodes || [];
for (let i = 0; i < nodes.length; i++) {
	let obj = await parser.getDependency('node', i);
	if (!inRoot(obj)) {
		// A node shared by several scenes is cloned into the later ones; find it by association.
		obj = null;
		root.traverse((o) => {
			const a = parser.associations.get(o);
			if (obj === null && a && a.nodes === i) obj = o;
		});
	}
	if (obj) {
		nodeObject.set(i, obj);
		nodeObjectSet.add(obj);
	}
}

// Drawables belonging to glTF node `i` itself (not to its glTF children), in primitive order.
function nodeDrawables(obj) {
	if (obj.isMesh || obj.isPoints || obj.isLine) return [obj];
	const out = [];
	const visit = (o) => {
		for (const c of o.children) {
			if (nodeObjectSet.has(c)) continue; // a glTF child node
			if (c.isMesh || c.isPoints || c.isLine) out.push(c);
			else if (c.isGroup) visit(c); // multi-primitive mesh group
		}
	};
	visit(obj);
	return out;
}

const fmt = (x) => {
	const v = Number(x.toPrecision(digits));
	return Object.is(v, -0) ? 0 : v;
};

const v = new THREE.Vector3();
const w = new THREE.Vector3();
const m4 = new THREE.Matrix4();
const v4 = new THREE.Vector4();
const v4b = new THREE.Vector4();
let skinCheckMax = 0;

function worldCorner(mesh, index, instanceMatrix) {
	mesh.getVertexPosition(index, v); // morph targets, then (SkinnedMesh) skinning, in mesh-local space
	if (instanceMatrix) v.applyMatrix4(instanceMatrix); // EXT_mesh_gpu_instancing: instance, then node
	v.applyMatrix4(mesh.matrixWorld);
	if (checkSkin && mesh.isSkinnedMesh) {
		// Direct glTF formula: sum_j w_j * jointWorld_j * inverseBind_j * morphed(v)
		THREE.Mesh.prototype.getVertexPosition.call(mesh, index, w);
		const si = mesh.geometry.attributes.skinIndex;
		const sw = mesh.geometry.attributes.skinWeight;
		v4b.set(w.x, w.y, w.z, 1).applyMatrix4(mesh.bindMatrix);
		let x = 0, y = 0, z = 0;
		for (let k = 0; k < 4; k++) {
			const wt = sw.getComponent(index, k);
			if (wt === 0) continue;
			const b = si.getComponent(index, k);
			m4.multiplyMatrices(mesh.skeleton.bones[b].matrixWorld, mesh.skeleton.boneInverses[b]);
			v4.copy(v4b).applyMatrix4(m4);
			x += wt * v4.x; y += wt * v4.y; z += wt * v4.z;
		}
		skinCheckMax = Math.max(skinCheckMax, Math.abs(x - v.x), Math.abs(y - v.y), Math.abs(z - v.z));
	}
	return [fmt(v.x), fmt(v.y), fmt(v.z)];
}

function triangles(mesh, instanceMatrix) {
	const g = mesh.geometry;
	const idx = g.index;
	const count = idx ? idx.count : g.attributes.position.count;
	const start = Math.max(0, g.drawRange.start);
	const end = Math.min(count, g.drawRange.start + g.drawRange.count);
	const out = [];
	for (let i = start; i + 2 < end; i += 3) {
		const tri = [];
		for (let k = 0; k < 3; k++) tri.push(worldCorner(mesh, idx ? idx.getX(i + k) : i + k, instanceMatrix));
		out.push(tri);
	}
	return out;
}

// ---- walk the default scene's node tree depth-first, pre-order, in file order -----------------
const result = { meshes: [], camera: null };
const sceneDef = (json.scenes || [])[sceneIndex] || { nodes: [] };
const visitNode = (i) => {
	const def = nodes[i];
	const obj = nodeObject.get(i);
	if (obj) {
		if (def.mesh !== undefined) {
			const drawables = nodeDrawables(obj);
			drawables.forEach((d, order) => {
				if (!d.isMesh) return; // points and lines draw no triangles
				const a = parser.associations.get(d) || {};
				const head = {
					node: i,
					mesh: a.meshes !== undefined ? a.meshes : def.mesh,
					primitive: a.primitives !== undefined ? a.primitives : order,
					skinned: d.isSkinnedMesh === true,
				};
				if (d.isInstancedMesh) {
					// One entry per instance, in instance order, each with "instance": k.
					const im = new THREE.Matrix4();
					for (let k = 0; k < d.count; k++) {
						d.getMatrixAt(k, im);
						const tris = triangles(d, im);
						if (tris.length) result.meshes.push({ ...head, instance: k, triangles: tris });
					}
					return;
				}
				const tris = triangles(d);
				if (tris.length === 0) return;
				result.meshes.push({ ...head, triangles: tris });
			});
		}
		if (def.camera !== undefined && result.camera === null) {
			let cam = obj.isCamera ? obj : obj.children.find((c) => c.isCamera && !nodeObjectSet.has(c));
			if (cam) {
				const p = new THREE.Vector3().setFromMatrixPosition(cam.matrixWorld);
				const f = new THREE.Vector3(0, 0, -1).transformDirection(cam.matrixWorld);
				const u = new THREE.Vector3(0, 1, 0).transformDirection(cam.matrixWorld);
				result.camera = {
					node: i,
					camera: def.camera,
					position: [fmt(p.x), fmt(p.y), fmt(p.z)],
					forward: [fmt(f.x), fmt(f.y), fmt(f.z)],
					up: [fmt(u.x), fmt(u.y), fmt(u.z)],
				};
			}
		}
	}
	for (const c of def.children || []) visitNode(c);
};
for (const n of sceneDef.nodes || []) visitNode(n);

if (clip) {
	const index = gltf.animations.indexOf(clip);
	// name: the glTF animation's own name (null if none; three calls such a clip animation_<i>).
	result.animation = { index, name: json.animations[index].name ?? null, duration: clip.duration, time };
}
if (normalizeRotations) result.normalize_rotations = true;
result.three = THREE.REVISION;
if (checkSkin) process.stderr.write(`check-skin: max |three - direct| = ${skinCheckMax}\n`);

console.log = origLog;
// One triangle a line: valid JSON, and fixtures diff readably.
const parts = [];
for (const [k, val] of Object.entries(result)) {
	if (k !== 'meshes') {
		parts.push(`${JSON.stringify(k)}:${JSON.stringify(val)}`);
		continue;
	}
	const ms = val.map((m) => {
		const { triangles, ...head } = m;
		const h = JSON.stringify(head).slice(0, -1);
		return `${h},"triangles":[\n${triangles.map((t) => JSON.stringify(t)).join(',\n')}\n]}`;
	});
	parts.push(`"meshes":[\n${ms.join(',\n')}\n]`);
}
process.stdout.write(`{${parts.join(',\n')}}\n`);
