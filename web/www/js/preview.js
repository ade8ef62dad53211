// The 3D toolpath preview: program.preview's polylines (computed by cncd's own interpreter and
// planner) as line segments coloured by kind, the part already run in grey, the live tool
// position as a cone, the machine's soft-limit box, top/front/side/iso views with
// pan/zoom/rotate, and a click on a segment picking its source line. Everything is drawn in
// machine coordinates, as the preview and the machine position come.

import * as THREE from '../vendor/three/build/three.module.js';
import {OrbitControls} from '../vendor/three/examples/jsm/controls/OrbitControls.js';

import {kDoneColor, kindCss} from './preview_colors.js';
import {decodeInPlace} from './preview_decode.js';
import {$, el, setText} from './ui.js';

const kViews = {
  top: new THREE.Vector3(0, -0.0001, 1),
  front: new THREE.Vector3(0, -1, 0),
  side: new THREE.Vector3(1, 0, 0),
  iso: new THREE.Vector3(1, -1, 0.8),
};

export function setupPreview(ctx) {
  const preview = new Preview(ctx, $('#preview'));
  ctx.preview = preview;
  for (const name of Object.keys(kViews))
    $(`#view-${name}`).addEventListener('click', () => preview.view(name));
  $('#preview-reload')
      .addEventListener('click', () => preview.load(ctx.store.status.program?.path ?? ''));
  $('#preview-legend')
      .replaceChildren(...['rapid', 'feed', 'arc', 'cycle', 'probe', 'done'].map(
          (kind) =>
              el('span', {class: 'legend-item'}, el('span', {
                   class: 'legend-swatch',
                   style: `background: ${kind === 'done' ? 'rgb(107,107,117)' : kindCss(kind)}`
                 }),
                 kind)));

  let loadedPath = null;
  ctx.on('program-opened', () => (loadedPath = null));
  // Asked again after a reconnection (the daemon may have restarted), not at the first one.
  ctx.on('connection', (up) => {
    if (!up) loadedPath = null;
  });
  ctx.on(
      'info',
      (info) => preview.setLimits(info?.machine?.limits ?? info?.machine?.soft_limits ?? null));
  ctx.store.subscribe((status) => {
    const program = status.program ?? {};
    const path = program.path ?? '';
    if (ctx.rpc.connected && path !== loadedPath && !program.opening) {
      loadedPath = path;
      preview.load(path);
    }
    preview.setTool(status.position?.actual);
    preview.follow(status);
  });
}

class Preview {
  constructor(ctx, canvas) {
    this.ctx = ctx;
    this.canvas = canvas;
    this.token = 0;
    this.path = null;
    this.segLine = null;
    this.baseColors = null;
    this.doneUpTo = 0;
    this.lastLine = 0;
    this.lastExec = 'idle';
    this.bounds = new THREE.Box3();
    this.frameRequested = false;
    try {
      this.renderer =
          new THREE.WebGLRenderer({canvas, antialias: true, preserveDrawingBuffer: true});
    } catch (e) {
      this.renderer = null;
      setText($('#preview-status'), `WebGL is not available: ${e.message}`);
      return;
    }
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.setClearColor(0x15171c);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1e6);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.screenSpacePanning = true;
    this.controls.addEventListener('change', () => this.requestRender());
    this.axes = new THREE.AxesHelper(1);
    this.scene.add(this.axes);
    this.tool = this.makeTool();
    this.tool.visible = false;
    this.scene.add(this.tool);
    this.lines = null;
    this.limits = null;
    this.setupPick();
    new ResizeObserver(() => this.resize()).observe(canvas.parentElement);
    this.resize();
    this.view('iso');
  }

  makeTool() {
    const geometry = new THREE.ConeGeometry(0.3, 1, 16);
    geometry.rotateX(-Math.PI / 2);  // apex down, on the tool point
    geometry.translate(0, 0, 0.5);
    return new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({color: 0xffd21f}));
  }

  resize() {
    if (!this.renderer) return;
    const box = this.canvas.parentElement;
    const width = Math.max(1, box.clientWidth);
    const height = Math.max(1, box.clientHeight);
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  requestRender() {
    if (!this.renderer || this.frameRequested) return;
    this.frameRequested = true;
    requestAnimationFrame(() => {
      this.frameRequested = false;
      this.renderer.render(this.scene, this.camera);
    });
  }

  // The size of everything drawn, for views and for the tool cone's and the pick's scale.
  sceneSize() {
    const size = new THREE.Vector3();
    if (this.bounds.isEmpty()) return 100;
    this.bounds.getSize(size);
    return Math.max(size.x, size.y, size.z, 1);
  }

  updateBounds() {
    this.bounds.makeEmpty();
    if (this.lines) this.bounds.union(this.lines.geometry.boundingBox);
    if (this.limits) this.bounds.union(this.limits.box);
    if (this.tool.visible) this.bounds.expandByPoint(this.tool.position);
    const scale = this.sceneSize() * 0.04;
    this.tool.scale.set(scale, scale, scale * 2);
    this.axes.scale.setScalar(this.sceneSize() * 0.1);
  }

  view(name) {
    if (!this.renderer) return;
    const center = new THREE.Vector3();
    if (this.bounds.isEmpty())
      center.set(0, 0, 0);
    else
      this.bounds.getCenter(center);
    const fov = (this.camera.fov * Math.PI) / 180;
    const distance = (this.sceneSize() * 0.75) / Math.tan(fov / 2);
    const direction = kViews[name].clone().normalize();
    this.camera.position.copy(center).addScaledVector(direction, distance);
    this.camera.near = distance / 1000;
    this.camera.far = distance * 100;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(center);
    this.controls.update();
    for (const key of Object.keys(kViews))
      $(`#view-${key}`).classList.toggle('active', key === name);
    this.requestRender();
  }

  // limits: {"X": [min, max], ...} in machine units, when the machine reports them.
  setLimits(limits) {
    if (!this.renderer) return;
    if (this.limits) this.scene.remove(this.limits);
    this.limits = null;
    const axis = (a) => limits?.[a] ?? limits?.[a.toLowerCase()];
    if (!limits || !axis('X') || !axis('Y')) return;
    const z = axis('Z') ?? [0, 0];
    const box = new THREE.Box3(
        new THREE.Vector3(axis('X')[0], axis('Y')[0], z[0]),
        new THREE.Vector3(axis('X')[1], axis('Y')[1], z[1]));
    this.limits = new THREE.Box3Helper(box, new THREE.Color(0x5a6270));
    this.scene.add(this.limits);
    this.updateBounds();
    this.requestRender();
  }

  setTool(position) {
    if (!this.renderer || !position) return;
    const {x = 0, y = 0, z = 0} = position;
    if (this.tool.visible && this.tool.position.x === x && this.tool.position.y === y &&
        this.tool.position.z === z)
      return;
    const first = !this.tool.visible;
    this.tool.position.set(x, y, z);
    this.tool.visible = true;
    if (first) this.updateBounds();
    this.requestRender();
  }

  async load(path) {
    const token = ++this.token;
    this.clearPath();
    setText($('#preview-pick'), '');
    if (!this.renderer) return;
    const status = $('#preview-status');
    if (!path) {
      setText(status, 'no program open');
      status.dataset.state = 'none';
      return;
    }
    setText(status, 'loading');
    status.dataset.state = 'loading';
    let result;
    try {
      result = await this.ctx.call('program.preview', {}, {quiet: true});
    } catch (e) {
      if (token !== this.token) return;
      // 1009: another program was opened meanwhile; its preview is asked for once it is open.
      if (e.code === 1009) {
        setText(status, 'loading');
        return;
      }
      setText(status, `preview failed: ${e.message}`);
      status.dataset.state = 'error';
      return;
    }
    if (token !== this.token) return;
    decodeInPlace(result);
    this.show(result);
    let text = `ready ${result.points} points`;
    if (result.tolerance !== undefined)
      text += ` · tolerance ${Number(result.tolerance.toPrecision(3))} ${result.units ?? ''}`;
    if (!result.complete) text += ` · incomplete: ${result.stopped ?? result.error ?? 'stopped'}`;
    setText(status, text);
    status.dataset.state = 'ready';
  }

  clearPath() {
    if (!this.lines) return;
    this.scene.remove(this.lines);
    this.lines.geometry.dispose();
    this.lines.material.dispose();
    this.lines = null;
    this.segLine = null;
    this.updateBounds();
    this.requestRender();
  }

  show(result) {
    const {positions, colors, segLine} = result.decoded;
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    const colorAttribute = new THREE.BufferAttribute(colors, 3);
    colorAttribute.setUsage?.(THREE.DynamicDrawUsage);
    geometry.setAttribute('color', colorAttribute);
    geometry.computeBoundingBox();
    geometry.computeBoundingSphere();
    const material = new THREE.LineBasicMaterial({vertexColors: THREE.VertexColors});
    this.lines = new THREE.LineSegments(geometry, material);
    this.scene.add(this.lines);
    this.segLine = segLine;
    this.baseColors = colors.slice();
    this.doneUpTo = 0;
    this.lastLine = 0;
    this.updateBounds();
    this.view(document.querySelector('.view-button.active')?.dataset.view ?? 'iso');
    this.follow(this.ctx.store.status);
  }

  // Greys the segments up to the running line. The run goes forward through the polylines, so
  // the next segment of the current line is searched from where the last one was found; a new
  // run starts over.
  follow(status) {
    if (!this.segLine) return;
    const exec = status.exec ?? 'idle';
    const line = status.program?.line ?? 0;
    if (exec !== 'idle' && this.lastExec === 'idle') this.resetDone();
    // A run that ended at its end has run every segment.
    if (exec === 'idle' && this.lastExec !== 'idle' && status.program?.result === 'done') {
      this.paint(this.doneUpTo, this.segLine.length, kDoneColor);
      this.doneUpTo = this.segLine.length;
    }
    this.lastExec = exec;
    if (exec === 'idle' || line === this.lastLine || line <= 0) return;
    this.lastLine = line;
    const count = this.segLine.length;
    let k = this.doneUpTo;
    while (k < count && this.segLine[k] !== line)
      ++k;
    if (k >= count || k === this.doneUpTo) return;
    this.paint(this.doneUpTo, k, kDoneColor);
    this.doneUpTo = k;
  }

  resetDone() {
    if (this.doneUpTo > 0) this.paint(0, this.doneUpTo, null);
    this.doneUpTo = 0;
    this.lastLine = 0;
  }

  paint(from, to, color) {
    const attribute = this.lines.geometry.getAttribute('color');
    const array = attribute.array;
    for (let i = from * 6; i < to * 6; i += 3) {
      if (color) {
        array[i] = color[0];
        array[i + 1] = color[1];
        array[i + 2] = color[2];
      } else {
        array[i] = this.baseColors[i];
        array[i + 1] = this.baseColors[i + 1];
        array[i + 2] = this.baseColors[i + 2];
      }
    }
    // Uploads only the changed range (joined with one not uploaded yet: three.js sets count back
    // to -1 once it has uploaded), not the whole path at each line.
    const range = attribute.updateRange;
    let start = from * 6;
    let end = to * 6;
    if (range.count !== -1) {
      start = Math.min(start, range.offset);
      end = Math.max(end, range.offset + range.count);
    }
    range.offset = start;
    range.count = end - start;
    attribute.needsUpdate = true;
    this.requestRender();
  }

  // A click (not a drag) on a segment picks its source line.
  setupPick() {
    const raycaster = new THREE.Raycaster();
    let down = null;
    this.canvas.addEventListener('pointerdown', (event) => (down = [event.clientX, event.clientY]));
    this.canvas.addEventListener('pointerup', (event) => {
      if (!down || Math.hypot(event.clientX - down[0], event.clientY - down[1]) > 6 || !this.lines)
        return;
      down = null;
      const rect = this.canvas.getBoundingClientRect();
      const ndc = new THREE.Vector2(
          ((event.clientX - rect.left) / rect.width) * 2 - 1,
          -((event.clientY - rect.top) / rect.height) * 2 + 1);
      raycaster.setFromCamera(ndc, this.camera);
      const distance = this.camera.position.distanceTo(this.controls.target);
      const perPixel = (2 * distance * Math.tan((this.camera.fov * Math.PI) / 360)) / rect.height;
      raycaster.params.Line.threshold = perPixel * 6;
      const hits = raycaster.intersectObject(this.lines);
      if (hits.length === 0) {
        setText($('#preview-pick'), 'nothing picked');
        return;
      }
      const line = this.segLine[Math.floor(hits[0].index / 2)];
      const text = this.ctx.programText?.lines[line - 1] ?? '';
      setText($('#preview-pick'), `line ${line}${text ? `: ${text.trim()}` : ''}`);
      $('#preview-pick').dataset.line = String(line);
      this.ctx.selectLine(line);
    });
  }
}
