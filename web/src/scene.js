// The 3D view: one group per object, one group per object frame (posed from the state frames),
// the object's shapes in its frames, links drawn between consecutive frames of a manipulator,
// gripper fingers that follow the gripper's state; OrbitControls for the mouse.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { STLLoader } from 'three/examples/jsm/loaders/STLLoader.js';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { ColladaLoader } from 'three/examples/jsm/loaders/ColladaLoader.js';
import { VRMLLoader } from 'three/examples/jsm/loaders/VRMLLoader.js';

const unitCylinder = new THREE.CylinderGeometry(1, 1, 1, 20); // along y, height 1
const unitBox = new THREE.BoxGeometry(1, 1, 1);
const unitSphere = new THREE.SphereGeometry(1, 20, 14);

function colorOf(c) {
  return new THREE.Color(c[0], c[1], c[2]);
}

// The URL of shape `index` of object `name`'s mesh: served by the program (only files its objects'
// models name), or the model's own http(s) URL.
function meshUrl(name, index, file) {
  if (/^https?:\/\//.test(file)) return file;
  const token = new URLSearchParams(location.search).get('token');
  return `mesh?object=${encodeURIComponent(name)}&shape=${index}${token ? `&token=${encodeURIComponent(token)}` : ''}`;
}

// Loads a mesh file (STL, glTF/GLB, Collada, VRML, by the file's extension) into `holder`.
function loadMesh(holder, url, file, material, onDone) {
  const ext = file.toLowerCase().split('.').pop();
  const done = (object) => {
    holder.add(object);
    object.traverse((c) => (c.userData.object = holder.userData.object));
    onDone(true);
  };
  const fail = () => onDone(false);
  if (ext === 'stl') new STLLoader().load(url, (g) => done(new THREE.Mesh(g, material)), undefined, fail);
  else if (ext === 'glb' || ext === 'gltf') new GLTFLoader().load(url, (g) => done(g.scene), undefined, fail);
  else if (ext === 'dae') new ColladaLoader().load(url, (c) => done(c.scene), undefined, fail);
  else if (ext === 'wrl') new VRMLLoader().load(url, (v) => done(v), undefined, fail);
  else fail();
}

export class SceneView {
  constructor(container) {
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xeef1f5);
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.01, 100);
    this.camera.up.set(0, 0, 1); // the robot world is z-up
    this.camera.position.set(2.2, -1.8, 1.6);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.target.set(0, 0, 0.5);
    this.controls.update();
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 1.2));
    const sun = new THREE.DirectionalLight(0xffffff, 1.5);
    sun.position.set(3, -2, 5);
    this.scene.add(sun);
    const grid = new THREE.GridHelper(4, 20, 0x8899aa, 0xc8d0da);
    grid.rotation.x = Math.PI / 2;
    this.scene.add(grid);
    this.scene.add(new THREE.AxesHelper(0.3));
    this.objects = new Map(); // name -> { root, frames, bones, fingers, desc, materials }
    this.meshes = { loaded: 0, failed: 0 };
    this.raycaster = new THREE.Raycaster();
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
    const loop = () => {
      requestAnimationFrame(loop);
      this.controls.update();
      this.renderer.render(this.scene, this.camera);
    };
    loop();
  }

  resize() {
    const w = this.container.clientWidth || 1;
    const h = this.container.clientHeight || 1;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
  }

  // Replaces the scene description (objects by path; unchanged objects keep their groups).
  setScene(scene) {
    const seen = new Set();
    for (const desc of scene.objects) {
      if (!desc.physical) continue;
      seen.add(desc.name);
      const old = this.objects.get(desc.name);
      const key = JSON.stringify([desc.frames, desc.shapes, desc.kind, desc.joints]);
      if (old && old.key === key) {
        old.desc = desc;
        this.applyDisplay(old);
        continue;
      }
      if (old) this.scene.remove(old.root);
      this.objects.set(desc.name, this.build(desc, key));
    }
    for (const [name, o] of this.objects)
      if (!seen.has(name)) {
        this.scene.remove(o.root);
        this.objects.delete(name);
      }
  }

  build(desc, key) {
    const root = new THREE.Group();
    root.name = desc.path;
    const materials = [];
    const material = (c) => {
      const m = new THREE.MeshStandardMaterial({ color: colorOf(c), roughness: 0.6, metalness: 0.2 });
      materials.push(m);
      return m;
    };
    const frames = (desc.frames || ['base']).map((name) => {
      const g = new THREE.Group();
      g.name = name;
      g.matrixAutoUpdate = false;
      root.add(g);
      return g;
    });
    const frameByName = new Map(frames.map((g) => [g.name, g]));
    (desc.shapes || []).forEach((s, shapeIndex) => {
      let mesh;
      if (s.kind === 'mesh' && s.mesh) {
        // A box of the given size until the file is loaded, then the mesh scaled by size.
        mesh = new THREE.Group();
        mesh.scale.set(s.size[0], s.size[1], s.size[2]);
        mesh.userData.object = desc.name;
        const mat = material(s.color);
        loadMesh(mesh, meshUrl(desc.name, shapeIndex, s.mesh), s.mesh, mat, (ok) => {
          if (ok) this.meshes.loaded++;
          else this.meshes.failed++;
        });
      } else if (s.kind === 'cylinder') {
        mesh = new THREE.Mesh(unitCylinder, material(s.color));
        mesh.scale.set(s.size[0], s.size[1], s.size[0]);
        mesh.rotation.x = Math.PI / 2; // the model's cylinders run along z
      } else if (s.kind === 'sphere') {
        mesh = new THREE.Mesh(unitSphere, material(s.color));
        mesh.scale.setScalar(s.size[0]);
      } else {
        // boxes, and meshes until their files are served: a box of the given size
        mesh = new THREE.Mesh(unitBox, material(s.color));
        mesh.scale.set(s.size[0], s.size[1], s.size[2]);
      }
      const holder = new THREE.Group();
      holder.matrixAutoUpdate = false;
      holder.matrix.fromArray(s.pose);
      holder.add(mesh);
      (frameByName.get(s.frame) || frames[0]).add(holder);
    });
    const o = { root, frames, desc, key, materials, bones: [], fingers: null };
    if (desc.kind === 'manipulator' && !desc.urdfVisuals) { // a URDF arm is drawn by its own visuals
      const linkMat = material([0.55, 0.6, 0.7, 1]);
      for (let i = 0; i + 1 < frames.length; ++i) {
        const bone = new THREE.Mesh(unitCylinder, linkMat);
        bone.visible = false;
        root.add(bone);
        o.bones.push(bone);
      }
    }
    if (desc.kind === 'gripper') {
      const fm = material([0.2, 0.25, 0.3, 1]);
      const left = new THREE.Mesh(unitBox, fm);
      const right = new THREE.Mesh(unitBox, fm);
      for (const f of [left, right]) {
        f.scale.set(0.015, 0.03, 0.08);
        f.position.z = 0.09;
        frames[0].add(f);
      }
      o.fingers = [left, right];
    }
    for (const m of root.children) m.userData.object = desc.name;
    root.traverse((c) => (c.userData.object = desc.name));
    this.scene.add(root);
    this.applyDisplay(o);
    return o;
  }

  applyDisplay(o) {
    const mode = o.desc.display || 'solid';
    o.root.visible = mode !== 'off';
    for (const m of o.materials) m.wireframe = mode === 'wireframe';
  }

  // Poses every object from a decoded state frame.
  setFrame(frame, scene) {
    if (!scene) return;
    const a = new THREE.Vector3();
    const b = new THREE.Vector3();
    const up = new THREE.Vector3(0, 1, 0);
    for (const s of frame.objects) {
      const desc = scene.objects[s.index];
      if (!desc) continue;
      const o = this.objects.get(desc.name);
      if (!o) continue;
      s.poses.forEach((m, i) => {
        if (o.frames[i]) {
          o.frames[i].matrix.fromArray(m);
          o.frames[i].matrixWorldNeedsUpdate = true;
        }
      });
      o.bones.forEach((bone, i) => {
        const pa = s.poses[i];
        const pb = s.poses[i + 1];
        if (!pa || !pb) return;
        a.set(pa[12], pa[13], pa[14]);
        b.set(pb[12], pb[13], pb[14]);
        const len = a.distanceTo(b);
        bone.visible = len > 1e-4;
        if (!bone.visible) return;
        bone.position.copy(a).add(b).multiplyScalar(0.5);
        bone.quaternion.setFromUnitVectors(up, b.clone().sub(a).normalize());
        bone.scale.set(0.035, len, 0.035);
      });
      if (o.fingers) {
        const state = s.values[0]; // 1 open, 2 closed (Gripper::State)
        const half = state === 2 ? 0.012 : 0.045;
        o.fingers[0].position.x = -half;
        o.fingers[1].position.x = half;
      }
    }
  }

  // The object name under the mouse at client coordinates, or null.
  pick(clientX, clientY) {
    const r = this.renderer.domElement.getBoundingClientRect();
    const p = new THREE.Vector2(((clientX - r.left) / r.width) * 2 - 1, -((clientY - r.top) / r.height) * 2 + 1);
    this.raycaster.setFromCamera(p, this.camera);
    const roots = [...this.objects.values()].filter((o) => o.root.visible).map((o) => o.root);
    // three.js' raycaster also hits what is not drawn: only a mesh that is visible, with every
    // parent visible (not a hidden object, a hidden link, or a link not placed yet), is picked.
    const shown = (obj) => {
      for (let x = obj; x; x = x.parent) if (!x.visible) return false;
      return true;
    };
    const hit = this.raycaster.intersectObjects(roots, true).find((h) => shown(h.object));
    return hit ? hit.object.userData.object : null;
  }

  // Screen position of an object's first frame (tests click there).
  screenPosition(name) {
    const o = this.objects.get(name);
    if (!o) return null;
    const v = new THREE.Vector3();
    o.frames[o.frames.length - 1].updateMatrixWorld(true);
    v.setFromMatrixPosition(o.frames[o.frames.length - 1].matrixWorld).project(this.camera);
    const r = this.renderer.domElement.getBoundingClientRect();
    return { x: r.left + ((v.x + 1) / 2) * r.width, y: r.top + ((1 - v.y) / 2) * r.height };
  }
}
