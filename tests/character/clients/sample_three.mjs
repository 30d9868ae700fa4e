// What three.js (and @pixiv/three-vrm) make of a file hairtool wrote: for every frame, the local
// rotation (x, y, z, w) of every animated node, as JSON on stdout.
//   node sample_three.mjs FILE FPS FRAMES clip          -> the file's own animation, sampled
//   node sample_three.mjs FILE FPS FRAMES springs TURN PERIOD HEAD
//        -> three-vrm's spring bones stepped once a frame while HEAD turns TURN degrees
//           about +Y, sin(2 pi t / PERIOD), as hairtool.character.springs.head_shake does
import fs from 'node:fs';
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { VRMLoaderPlugin } from '@pixiv/three-vrm';

const [file, fpsText, framesText, mode, turnText, periodText, headName] = process.argv.slice(2);
const fps = Number(fpsText);
const frames = Number(framesText);
const bytes = fs.readFileSync(file);
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
const loader = new GLTFLoader();
loader.register((parser) => new VRMLoaderPlugin(parser, { autoUpdateHumanBones: false }));
const gltf = await new Promise((resolve, reject) => loader.parse(buffer, '', resolve, reject));
const byName = {};
gltf.scene.traverse((o) => { byName[o.name] = o; });
const out = [];
if (mode === 'clip') {
  const clip = gltf.animations[gltf.animations.length - 1];
  const names = clip.tracks.map((t) => t.name.split('.')[0]);
  const mixer = new THREE.AnimationMixer(gltf.scene);
  // played once and held at its end: a repeating action wraps its last key time back to 0
  const action = mixer.clipAction(clip);
  action.setLoop(THREE.LoopOnce, 1);
  action.clampWhenFinished = true;
  action.play();
  for (let f = 0; f < frames; f++) {
    mixer.setTime(f / fps);
    const row = {};
    for (const n of names) row[n] = byName[n].quaternion.toArray();
    out.push(row);
  }
} else {
  const vrm = gltf.userData.vrm;
  const turn = Number(turnText) * Math.PI / 180;
  const period = Number(periodText);
  const head = byName[headName];
  const rest = head.quaternion.clone();
  const joints = [...vrm.springBoneManager.joints].map((j) => j.bone.name);
  const up = new THREE.Vector3(0, 1, 0);
  for (let f = 0; f < frames; f++) {
    const q = new THREE.Quaternion().setFromAxisAngle(up, turn * Math.sin(2 * Math.PI * (f / fps) / period));
    head.quaternion.copy(q.multiply(rest));
    gltf.scene.updateMatrixWorld(true);
    vrm.springBoneManager.update(1 / fps);
    const row = {};
    for (const n of joints) row[n] = byName[n].quaternion.toArray();
    out.push(row);
  }
}
process.stdout.write(JSON.stringify(out));
