// The 3D view: one group per object, one group per object frame (posed from the state frames),
// the object's shapes in its frames, links drawn between consecutive frames of a manipulator,
// gripper fingers that follow the gripper's state; OrbitControls for the mouse (the camera stays
// above the floor), a reset of the view, each frame's axes on demand, and the end-effector poses.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { STLLoader } from 'three/examples/jsm/loaders/STLLoader.js';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { ColladaLoader } from 'three/examples/jsm/loaders/ColladaLoader.js';
import { VRMLLoader } from 'three/examples/jsm/loaders/VRMLLoader.js';
import { OBJLoader } from 'three/examples/jsm/loaders/OBJLoader.js';

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

// Loads a mesh file (STL, Collada, Wavefront OBJ, glTF/GLB, VRML, by the file's extension) into
// `holder`; `onDone(null)` when it is drawn, `onDone(message)` when it cannot be. STL and OBJ files
// (no colours of their own) are drawn with `material` (the URDF's colour); the materials a file
// brings are added to `materials` (for the display mode).
function loadMesh(holder, url, file, material, materials, onDone) {
  const ext = file.toLowerCase().split('.').pop();
  const done = (object) => {
    if (!object || !object.isObject3D) {
      onDone('the file holds no drawable scene');
      return;
    }
    holder.add(object);
    object.traverse((c) => {
      c.userData.object = holder.userData.object;
      // Files without normals (or with zero ones, as many STL exporters write) would be drawn
      // black: their faces' normals are computed, as RViz does.
      const normal = c.isMesh && c.geometry && c.geometry.getAttribute('normal');
      if (c.isMesh && c.geometry && (!normal || normal.array.every((x) => x === 0))) c.geometry.computeVertexNormals();
      if (c.material) for (const m of [].concat(c.material)) if (m !== material && !materials.includes(m)) materials.push(m);
    });
    onDone(null);
  };
  const fail = (e) => onDone(String((e && e.message) || e || 'cannot be loaded').slice(0, 200));
  // A loader whose callback throws (a file it cannot parse) reports it through fail().
  const guard = (f) => (x) => {
    try {
      f(x);
    } catch (e) {
      fail(e);
    }
  };
  if (ext === 'stl') new STLLoader().load(url, guard((g) => done(new THREE.Mesh(g, material))), undefined, fail);
  else if (ext === 'obj') {
    new OBJLoader().load(url, guard((o) => {
      o.traverse((c) => {
        if (c.isMesh) c.material = material;
      });
      done(o);
    }), undefined, fail);
  } else if (ext === 'glb' || ext === 'gltf') new GLTFLoader().load(url, guard((g) => done(g.scene)), undefined, fail);
  else if (ext === 'dae') {
    new ColladaLoader().load(url, guard((c) => {
      if (!c || !c.scene) throw new Error('not a Collada file');
      // A URDF mesh's vertices are in its link's frame whatever the file's up axis says: undo the
      // loader's turn of Z_UP files to three.js' Y up (its unit scale, <unit meter>, is kept).
      c.scene.rotation.set(0, 0, 0);
      done(c.scene);
    }), undefined, fail);
  } else if (ext === 'wrl') new VRMLLoader().load(url, guard((v) => done(v)), undefined, fail);
  else fail(`the format .${ext} is not drawn`);
}

// A primitive shape of the scene (box, cylinder along z, sphere) as a three.js mesh.
function primitive(s, material) {
  let mesh;
  if (s.kind === 'cylinder') {
    mesh = new THREE.Mesh(unitCylinder, material);
    mesh.scale.set(s.size[0], s.size[1], s.size[0]);
    mesh.rotation.x = Math.PI / 2; // the model's cylinders run along z
  } else if (s.kind === 'sphere') {
    mesh = new THREE.Mesh(unitSphere, material);
    mesh.scale.setScalar(s.size[0]);
  } else {
    mesh = new THREE.Mesh(unitBox, material);
    mesh.scale.set(s.size[0], s.size[1], s.size[2]);
  }
  return mesh;
}

// The side of the cube drawn in place of a mesh that cannot be drawn and has no collision geometry [m].
const PLACEHOLDER_SIZE = 0.04;
const PLACEHOLDER_COLOR = [0.9, 0.1, 0.7, 1];

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
    // The camera stays above the floor (z = 0): it never looks up from below the target, and the
    // target is never panned below the floor.
    this.controls.maxPolarAngle = Math.PI / 2 - 0.02;
    this.controls.addEventListener('change', () => {
      if (this.controls.target.z < 0) {
        this.camera.position.z -= this.controls.target.z;
        this.controls.target.z = 0;
      }
    });
    this.controls.update();
    this.defaultDirection = this.camera.position.clone().sub(this.controls.target).normalize();
    this.framesShown = false;
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
    // Called with (object, shape, message) when a mesh file the server named cannot be drawn
    // (the page tells the server, which reports it on stderr).
    this.onMeshFailed = null;
    // The view frames the scene when the page opens and as meshes arrive, until the user moves it.
    this.refit = true;
    this.userMoved = false;
    this.fits = 0;
    this.controls.addEventListener('start', () => (this.userMoved = true));
    this.raycaster = new THREE.Raycaster();
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
    const loop = () => {
      requestAnimationFrame(loop);
      this.controls.update();
      this.placeLabels();
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
      if (old) this.remove(old);
      this.objects.set(desc.name, this.build(desc, key));
      this.refit = true;
    }
    for (const [name, o] of this.objects)
      if (!seen.has(name)) {
        this.remove(o);
        this.objects.delete(name);
      }
  }

  remove(o) {
    this.scene.remove(o.root);
    if (o.label) o.label.remove();
  }

  // Shows each object's drawing problems (meshes not drawn, URDF visuals not read) next to it.
  placeLabels() {
    const v = new THREE.Vector3();
    for (const o of this.objects.values()) {
      if (!o.problems.length) continue;
      if (!o.label) {
        o.label = document.createElement('div');
        o.label.className = 'mesh-problems';
        o.label.dataset.object = o.desc.name;
        this.container.appendChild(o.label);
      }
      // The places looked at are on the program's stderr (and in the tooltip), not in the note.
      const full = `${o.desc.name}: drawn without\n${o.problems.map((p) => p.text).join('\n')}`;
      const text = full.replace(/ \(looked in [^)]*\)/g, '');
      if (o.label.textContent !== text) {
        o.label.textContent = text;
        o.label.title = full;
      }
      const frame = o.frames[0]; // the object's base: the note stays clear of a moving arm
      frame.updateWorldMatrix(true, false);
      v.setFromMatrixPosition(frame.matrixWorld).project(this.camera);
      const w = this.container.clientWidth;
      const h = this.container.clientHeight;
      const inside = v.z < 1 && Math.abs(v.x) <= 1 && Math.abs(v.y) <= 1;
      // Below and right of the object's base, kept inside the view.
      const x = ((inside ? v.x : 0) + 1) / 2 * w + 12;
      const y = (1 - (inside ? v.y : 0.9)) / 2 * h + 12;
      o.label.style.left = `${Math.round(Math.max(0, Math.min(x, w - o.label.offsetWidth)))}px`;
      o.label.style.top = `${Math.round(Math.max(0, Math.min(y, h - o.label.offsetHeight)))}px`;
      o.label.hidden = !o.root.visible;
    }
  }

  // Points the camera at the bounding box of every object drawn, from the current direction.
  fitView() {
    const box = new THREE.Box3();
    this.scene.updateMatrixWorld(true);
    // Each geometry's own bounding box, transformed (cheap; a little larger than the exact box).
    for (const o of this.objects.values()) if (o.root.visible) box.expandByObject(o.root);
    if (box.isEmpty()) return false;
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    const radius = Math.max(sphere.radius, 0.05);
    const fov = THREE.MathUtils.degToRad(this.camera.fov);
    const fit = Math.min(fov, 2 * Math.atan(Math.tan(fov / 2) * this.camera.aspect)) / 2;
    const distance = (1.15 * radius) / Math.sin(fit);
    const direction = this.camera.position.clone().sub(this.controls.target).normalize();
    this.controls.target.copy(sphere.center);
    this.camera.position.copy(sphere.center).addScaledVector(direction, distance);
    this.camera.near = Math.max(distance / 1000, 0.001);
    this.camera.far = Math.max(100, distance * 10);
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.fits++;
    return true;
  }

  // Back to the view the page opened with: the default direction, framing every object drawn
  // (and framing again as meshes arrive, until the user moves the view).
  resetView() {
    this.camera.position.copy(this.controls.target).add(this.defaultDirection);
    this.userMoved = false;
    this.refit = false;
    if (!this.fitView()) this.controls.update();
  }

  // Shows or hides the axes of every frame of every object (x red, y green, z blue).
  showFrames(on) {
    this.framesShown = on;
    for (const o of this.objects.values()) for (const a of o.axes) a.visible = on;
  }

  // The world pose of each manipulator's end-effector frame: { name, position [mm], rpy [deg] }
  // (roll, pitch and yaw about the fixed x, y and z axes, as rp::transformToRPY gives them).
  endEffectorPoses() {
    const out = [];
    const m = new THREE.Matrix4();
    const p = new THREE.Vector3();
    const q = new THREE.Quaternion();
    const scale = new THREE.Vector3();
    const e = new THREE.Euler();
    for (const o of this.objects.values()) {
      if (o.desc.kind !== 'manipulator') continue;
      const frame = o.frames.find((f) => f.name === 'endEffector');
      if (!frame) continue;
      frame.updateWorldMatrix(true, false);
      m.copy(frame.matrixWorld).decompose(p, q, scale);
      e.setFromQuaternion(q, 'ZYX'); // R = Rz(yaw) Ry(pitch) Rx(roll)
      out.push({ name: o.desc.name, position: p.toArray().map((x) => x * 1000),
        rpy: [e.x, e.y, e.z].map((x) => THREE.MathUtils.radToDeg(x)) });
    }
    return out;
  }

  // For tests and the console (read only): what is drawn for each shape of object `name`: kind,
  // URDF link, frame, state ('primitive', 'loading', 'mesh', 'fallback', 'placeholder'), error,
  // texture (null: none; 'loading', 'drawn', 'failed'), and the world-space bounding box of what
  // is drawn for it ({ min, max }, null if nothing).
  drawnShapes(name) {
    const o = this.objects.get(name);
    if (!o) return null;
    o.root.updateWorldMatrix(true, true);
    return o.drawn.map((d) => {
      const box = new THREE.Box3();
      for (const h of d.objects) box.expandByObject(h, true);
      return {
        kind: d.kind, link: d.link, frame: d.frame, state: d.state, error: d.error, texture: d.texture,
        box: box.isEmpty() ? null : { min: box.min.toArray(), max: box.max.toArray() },
      };
    });
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
    // Each frame's axes, shown on demand (showFrames()); not pickable.
    const axes = frames.map((g) => {
      const a = new THREE.AxesHelper(desc.kind === 'manipulator' ? 0.12 : 0.08);
      a.visible = this.framesShown;
      a.raycast = () => {};
      a.material.depthTest = false; // drawn over the links they sit in
      a.renderOrder = 1;
      g.add(a);
      return a;
    });
    // Per shape, what is drawn for it: state 'primitive', 'loading', 'mesh', 'fallback' (the
    // link's collision geometry) or 'placeholder', with the three.js objects and any error.
    const drawn = [];
    const problems = []; // { frame, text } shown next to the object
    const fallbackLinks = new Set(); // links whose collision geometry is drawn already
    const frameOf = (s) => frameByName.get(s.frame) || frames[0];
    const placed = (s, child) => {
      const holder = new THREE.Group();
      holder.matrixAutoUpdate = false;
      holder.matrix.fromArray(s.pose);
      holder.add(child);
      child.traverse((c) => (c.userData.object = desc.name));
      frameOf(s).add(holder);
      return holder;
    };
    // A mesh (of a visual, or of a link's collision geometry) loaded into a group scaled by its size.
    const meshGroup = (s, meshShape, onDone, mat = material(s.color)) => {
      const g = new THREE.Group();
      g.scale.set(s.size[0], s.size[1], s.size[2]);
      g.userData.object = desc.name;
      loadMesh(g, meshUrl(desc.name, meshShape, s.mesh), s.mesh, mat, materials, (error) => {
        if (error) this.meshes.failed++;
        else this.meshes.loaded++;
        this.refit = true;
        onDone(error);
      });
      return g;
    };
    const placeholder = (s, d) => {
      const m = primitive({ kind: 'box', size: [PLACEHOLDER_SIZE, PLACEHOLDER_SIZE, PLACEHOLDER_SIZE] }, material(PLACEHOLDER_COLOR));
      d.objects.push(placed(s, m));
      d.state = 'placeholder';
    };
    // Mesh `shapeIndex` cannot be drawn: report it and draw the link's collision geometry instead
    // (once per link), or a placeholder where the visual is.
    const standIn = (s, shapeIndex, error) => {
      const d = drawn[shapeIndex];
      for (const h of d.objects) h.parent && h.parent.remove(h);
      d.objects = [];
      d.error = error;
      const name = s.uri || s.mesh;
      problems.push({ frame: s.frame, text: `${s.link ? `${s.link}: ` : ''}${name}: ${error}` });
      if (this.onMeshFailed && !s.meshError) this.onMeshFailed(desc.name, shapeIndex, error);
      const collision = s.fallback || [];
      if (collision.length && !fallbackLinks.has(s.link)) {
        fallbackLinks.add(s.link);
        d.state = 'fallback';
        for (const c of collision) {
          if (c.kind === 'mesh') {
            const g = meshGroup(c, c.meshShape, (e) => {
              if (e) placeholder(c, d);
            });
            d.objects.push(placed(c, g));
          } else {
            d.objects.push(placed(c, primitive(c, material(c.color))));
          }
        }
      } else if (collision.length) {
        d.state = 'fallback'; // the link's collision geometry is drawn for another of its visuals
      } else {
        placeholder(s, d);
      }
      this.refit = true;
    };
    // A shape's material: its colour, and the URDF material's texture image (served as meshes are).
    const shapeMaterial = (s, d) => {
      const m = material(s.color);
      if (!s.texture) return m;
      const name = s.texture.uri;
      if (s.texture.error) {
        d.texture = 'failed';
        problems.push({ frame: s.frame, text: `${s.link ? `${s.link}: ` : ''}texture ${name}: ${s.texture.error}` });
        return m;
      }
      d.texture = 'loading';
      new THREE.TextureLoader().load(meshUrl(desc.name, s.texture.meshShape, name), (t) => {
        t.colorSpace = THREE.SRGBColorSpace;
        m.map = t;
        m.needsUpdate = true;
        d.texture = 'drawn';
      }, undefined, () => {
        d.texture = 'failed';
        problems.push({ frame: s.frame, text: `${s.link ? `${s.link}: ` : ''}texture ${name}: cannot be loaded` });
        if (this.onMeshFailed) this.onMeshFailed(desc.name, s.texture.meshShape, 'the texture image cannot be loaded');
      });
      return m;
    };
    (desc.shapes || []).forEach((s, shapeIndex) => {
      const d = { kind: s.kind, link: s.link || null, frame: s.frame, state: 'primitive', error: null, objects: [],
        texture: null };
      drawn.push(d);
      if (s.kind === 'mesh' && s.meshError) {
        standIn(s, shapeIndex, s.meshError);
      } else if (s.kind === 'mesh' && s.mesh) {
        d.state = 'loading';
        const g = meshGroup(s, shapeIndex, (error) => {
          if (error) standIn(s, shapeIndex, error);
          else d.state = 'mesh';
        }, shapeMaterial(s, d));
        d.objects.push(placed(s, g));
      } else {
        d.objects.push(placed(s, primitive(s, shapeMaterial(s, d))));
      }
    });
    if (desc.urdfError) problems.push({ frame: 'base', text: `URDF visuals: ${desc.urdfError}` });
    const o = { root, frames, axes, desc, key, materials, bones: [], fingers: null, drawn, problems, label: null };
    // A URDF arm is drawn by its own visuals, a DH arm by the links its model draws; other arms
    // get a cylinder between consecutive frames.
    if (desc.kind === 'manipulator' && !desc.urdfVisuals && !desc.linksDrawn) {
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
    if (this.refit && !this.userMoved) {
      this.refit = false;
      this.fitView();
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
