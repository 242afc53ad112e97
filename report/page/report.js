// The job report's script (docs/report.md): reads the data document inlined in the page,
// builds the 3D view with three.js (r111, inlined beside this script) and the panels.
// window.hybridctlReport exposes the state the browser test checks (tests/report/).
'use strict';
(function () {
  const data = JSON.parse(document.getElementById('report-data').textContent);
  const report = { ready: false, errors: [], framed: null, layer: null, shown: null, exactPlan: null, visible: {} };
  window.hybridctlReport = report;

  // One colour per meaning, shared with the PNG snapshots (report/report.cpp).
  const kColours = {
    design: 0x9eadc2, violating: 0xdc1a1f, 'must-in': 0x3f9a5b, 'must-out': 0x9aa3ad, free: 0xe0c341,
    additive: 0xd99e5c, subtractive: 0x859ebd, rapid: 0xd933bf, feed: 0x737379, deposit: 0xe65a0d, cut: 0x0d8ccc,
    current: 0x111111, built: 0xb0b8c4, over_within: 0xf4a259, over_beyond: 0xc8161d, under_within: 0x7fb7e6,
    under_beyond: 0x1d3fbf, alarm: 0xff00aa, place: 0x7a1fa2,
  };
  // The exact deviation's scale, as report/report_exact.cpp's exact_colour (the snapshots):
  // neutral at 0, to orange at +tolerance (excess) and to blue at -tolerance (gouge); beyond
  // the tolerance a flat dark red or dark violet, and the facet outlined in yellow; facets
  // left as deposited dashed in green.
  const kExact = { neutral: 0xdde1e6, excess: 0xf08a24, excessBeyond: 0xb3121a, gouge: 0x3a86d4, gougeBeyond: 0x3b1a86,
                   outline: 0xffd21f, deposited: 0x13a84a };
  const kPrimitiveColours = [0x4e79a7, 0xf28e2b, 0x59a14f, 0xb07aa1, 0x76b7b2, 0xedc948, 0xff9da7, 0x9c755f, 0xbab0ac, 0xe15759];
  const degToRad = (THREE.MathUtils || THREE.Math).degToRad;  // THREE.Math until r113
  const kViewDirection = new THREE.Vector3(1.0, -1.6, 1.1).normalize();  // as report/snapshot.cpp

  // ---- decoding --------------------------------------------------------------------------
  function bytes(b64) {
    const s = atob(b64), out = new Uint8Array(s.length);
    for (let i = 0; i < s.length; ++i) out[i] = s.charCodeAt(i);
    return out;
  }
  function decodeMesh(m) {
    if (!m || !m.p) return null;
    const q = new Uint16Array(bytes(m.p).buffer), pos = new Float32Array(q.length);
    for (let i = 0; i < q.length; ++i) {
      const k = i % 3;
      pos[i] = m.lo[k] + (q[i] / 65535) * (m.hi[k] - m.lo[k]);
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    const index = m.i16 ? new Uint16Array(bytes(m.i16).buffer) : new Uint32Array(bytes(m.i32).buffer);
    g.setIndex(new THREE.BufferAttribute(index, 1));
    g.computeBoundingBox();
    g.computeBoundingSphere();
    return g;
  }
  function meshOf(m, colour, opacity) {
    const g = decodeMesh(m);
    if (!g) return null;
    const material = new THREE.MeshPhongMaterial({
      color: colour, flatShading: true, side: THREE.DoubleSide, shininess: 20,
      transparent: opacity < 1, opacity: opacity, depthWrite: opacity >= 1,
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    return new THREE.Mesh(g, material);
  }
  const fmt = (v, d) => (typeof v === 'number' && isFinite(v) ? v.toFixed(d === undefined ? 1 : d) : '–');
  const vol = (v) => (typeof v === 'number' ? (v >= 1000 ? (v / 1000).toFixed(2) + ' cm³' : v.toFixed(1) + ' mm³') : '–');
  const xyz = (p) => (Array.isArray(p) ? '(' + p.map((c) => fmt(c, 1)).join(', ') + ')' : '–');
  function duration(s) {
    if (typeof s !== 'number') return '–';
    if (s < 60) return s.toFixed(1) + ' s';
    if (s < 3600) return Math.floor(s / 60) + ' min ' + Math.round(s % 60) + ' s';
    return Math.floor(s / 3600) + ' h ' + String(Math.floor((s % 3600) / 60)).padStart(2, '0') + ' min';
  }
  function el(tag, cls, text) {
    const e = document.createElement(tag);
    if (cls) e.className = cls;
    if (text !== undefined) e.textContent = text;
    return e;
  }

  // ---- the 3D view ------------------------------------------------------------------------
  const canvas = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ canvas: canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0xf5f7fa, 1);
  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera(35, 1, 0.1, 10000);
  camera.up.set(0, 0, 1);
  scene.add(new THREE.AmbientLight(0xffffff, 0.5));
  const sun = new THREE.DirectionalLight(0xffffff, 0.65);
  camera.add(sun);
  sun.position.set(0.4, 0.8, 0.5);
  scene.add(camera);
  const controls = new THREE.OrbitControls(camera, canvas);
  controls.enableDamping = false;
  controls.addEventListener('change', requestRender);

  let renderPending = false;
  function requestRender() {
    if (renderPending) return;
    renderPending = true;
    requestAnimationFrame(() => { renderPending = false; renderer.render(scene, camera); });
  }
  function resize() {
    const r = canvas.parentElement.getBoundingClientRect();
    renderer.setSize(r.width, r.height, false);
    camera.aspect = r.width / Math.max(1, r.height);
    camera.updateProjectionMatrix();
    requestRender();
  }
  window.addEventListener('resize', resize);

  function frame(box, margin) {
    if (!box || box.isEmpty()) return;
    const centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3());
    const radius = Math.max(size.length() / 2, 1) * (margin || 1.15);
    const distance = radius / Math.sin(degToRad(camera.fov / 2)) / Math.min(1, camera.aspect);
    camera.position.copy(centre).addScaledVector(kViewDirection, distance);
    camera.near = distance / 100;
    camera.far = distance * 100;
    camera.updateProjectionMatrix();
    controls.target.copy(centre);
    controls.update();
    requestRender();
  }

  // Everything that can be shown, by name: the toggles, the panels and the test use these.
  const layers = {};
  function addLayer(name, object, visible, info) {
    if (!object) return null;
    object.name = name;
    object.visible = !!visible;
    object.userData.info = info || name;
    scene.add(object);
    layers[name] = object;
    report.visible[name] = object.visible;
    return object;
  }
  function setVisible(name, on) {
    const o = layers[name];
    if (!o) return;
    o.visible = on;
    report.visible[name] = on;
    const box = document.querySelector('input[data-layer="' + CSS.escape(name) + '"]');
    if (box) box.checked = on;
    updateLegend();
    requestRender();
  }
  function toggle(container, name, label, colour, note) {
    if (!layers[name]) return;
    const row = el('label');
    const box = el('input');
    box.type = 'checkbox';
    box.checked = layers[name].visible;
    box.dataset.layer = name;
    box.addEventListener('change', () => setVisible(name, box.checked));
    row.append(box);
    const sw = el('span', 'swatch');
    sw.style.background = '#' + colour.toString(16).padStart(6, '0');
    row.append(sw, el('span', '', label));
    if (note) row.append(el('span', 'note', note));
    container.append(row);
  }
  const legendEntries = [];
  function updateLegend() {
    const legend = document.getElementById('legend');
    legend.textContent = '';
    for (const [name, label, colour] of legendEntries) {
      if (!layers[name] || !layers[name].visible) continue;
      const item = el('span');
      const sw = el('span', 'swatch');
      sw.style.background = '#' + colour.toString(16).padStart(6, '0');
      item.append(sw, label);
      legend.append(item);
    }
  }

  // ---- design, primitives, atoms, verdict ---------------------------------------------------
  function buildHeader() {
    const h = document.getElementById('header');
    const part = String(data.part || 'part').split('/').pop();
    h.append(el('h1', '', part));
    const v = data.verdict || {};
    // plan.json's outcome, as `plan` says it. Plans written before it carried one: undecided
    // when the search stopped at its limits or learned from rejected candidates, and
    // nothing decided the part before the search.
    const outcome = v.outcome || (v.manufacturable ? 'manufacturable'
                    : !v.decided_without_search && ((data.search && data.search.limit_reached) ||
                                                    (data.learned || []).length > 0) ? 'undecided' : 'not-manufacturable');
    h.append(el('span', 'badge ' + (outcome === 'manufacturable' ? 'ok' : 'bad'),
                outcome === 'manufacturable' ? 'manufacturable' : outcome === 'undecided' ? 'UNDECIDED' : 'NOT manufacturable'));
    const facts = [(data.machine && data.machine.name) || '', 'voxel ' + fmt(data.voxel_size, 2) + ' mm',
                   'tolerance ' + fmt(data.tolerance, 2) + ' mm', (data.atoms ? data.atoms.count : 0) + ' atoms',
                   (data.primitives || []).length + ' primitives', (data.plans || []).length + ' plans'];
    h.append(el('span', 'facts', facts.filter(Boolean).join(' · ')));
  }

  function buildModel() {
    const list = document.getElementById('layers');
    const d = data.design || {};
    addLayer('design', meshOf(d.mesh, kColours.design, 1), true, 'design\nvolume ' + vol(d.volume));
    list.append(el('div', 'group', 'Design'));
    toggle(list, 'design', 'design', kColours.design, vol(d.volume));
    legendEntries.push(['design', 'design', kColours.design]);
    list.append(el('div', 'group', 'Primitives'));
    (data.primitives || []).forEach((p, i) => {
      const colour = kPrimitiveColours[i % kPrimitiveColours.length];
      const info = p.name + ': ' + (p.label || '') + '\n' + (p.mode || '') + ', volume ' + vol(p.volume);
      addLayer(p.name, meshOf(p.mesh, colour, 0.45), false, info);
      toggle(list, p.name, p.name + ' ' + (p.label || ''), colour, p.mode === 'additive' ? 'AM' : 'SM');
      legendEntries.push([p.name, p.name, colour]);
    });
    list.append(el('div', 'group', 'Atoms by class'));
    const classes = (data.atoms && data.atoms.classes) || {};
    for (const cls of ['must-in', 'must-out', 'free']) {
      const c = classes[cls];
      if (!c) continue;
      const name = 'atoms:' + cls;
      addLayer(name, meshOf(c.mesh, kColours[cls], cls === 'must-in' ? 1 : 0.35), false,
               cls + ' atoms\n' + c.atoms + ' atoms, ' + vol(c.volume));
      toggle(list, name, cls, kColours[cls], c.atoms + ' · ' + vol(c.volume));
      legendEntries.push([name, cls, kColours[cls]]);
    }
  }

  function buildVerdict() {
    const panel = document.getElementById('verdict-panel');
    const v = data.verdict || {};
    panel.append(el('h2', '', 'Verdict'));
    panel.append(el('div', '', v.summary || ''));
    // The refusal's places in a shop's words (plan.json verdict.in_shop_words), as `plan` prints them.
    (v.in_shop_words || []).forEach((line) => panel.append(el('div', 'in-shop-words', line)));
    const violations = v.violations || [];
    if (!violations.length) return;
    const group = new THREE.Group();
    const frames = new THREE.Group();
    violations.forEach((a) => {
      const info = 'violating atom ' + a.atom + ' (' + (a.code || '') + ')\nvolume ' + vol(a.volume) + ', in design ' +
                   vol(a.volume_in_design) + '\ncentroid ' + xyz(a.centroid) + '\n' + (a.description || '');
      const m = meshOf(a.mesh, kColours.violating, 1);
      if (m) { m.userData.info = info; m.userData.atom = a.atom; group.add(m); }
      const bb = a.bounding_box;
      if (bb && bb.min && bb.max) {
        const box = new THREE.Box3(new THREE.Vector3(...bb.min), new THREE.Vector3(...bb.max));
        const helper = new THREE.Box3Helper(box, kColours.violating);
        helper.userData.atom = a.atom;
        helper.userData.box = box;
        frames.add(helper);
      }
    });
    addLayer('violating', group, true, 'violating atoms');
    addLayer('violating:frames', frames, true, 'frames of the violating atoms');
    legendEntries.push(['violating', 'violating atom', kColours.violating]);
    // Show them through the design: the design turns translucent while they are listed.
    if (layers.design) { layers.design.material.transparent = true; layers.design.material.opacity = 0.35;
                         layers.design.material.depthWrite = false; }
    panel.append(el('h3', '', violations.length + ' offending atom' + (violations.length > 1 ? 's' : '')));
    violations.forEach((a) => {
      const item = el('div', 'violation');
      item.dataset.atom = a.atom;
      item.append(el('div', '', 'Atom ' + a.atom + ' · ' + vol(a.volume) + ' (' + vol(a.volume_in_design) + ' in the design)'));
      item.append(el('div', '', a.description || ''));
      item.append(el('div', 'where', 'at ' + xyz(a.centroid) + ' · in ' + ((a.primitives || []).join(', ') || 'no primitive')));
      item.addEventListener('click', () => frameAtom(a.atom));
      panel.append(item);
    });
    const list = document.getElementById('layers');
    list.append(el('div', 'group', 'Verdict'));
    toggle(list, 'violating', 'violating atoms', kColours.violating, String(violations.length));
    toggle(list, 'violating:frames', 'their frames', kColours.violating);
  }

  function frameAtom(id) {
    const frames = layers['violating:frames'];
    if (!frames) return;
    let target = null;
    frames.children.forEach((h) => {
      const on = h.userData.atom === id;
      h.material.color.setHex(on ? 0x000000 : kColours.violating);
      if (on) target = h.userData.box;
    });
    document.querySelectorAll('.violation').forEach((e) => e.classList.toggle('framed', Number(e.dataset.atom) === id));
    setVisible('violating', true);
    setVisible('violating:frames', true);
    report.framed = id;
    // Some room around the atom, so its frame and what is next to it show.
    if (target) frame(target.clone().expandByScalar(Math.max(2, 0.15 * target.getSize(new THREE.Vector3()).length())), 1.1);
    setCaption('Offending atom ' + id);
  }
  function setCaption(text) { document.getElementById('view-caption').textContent = text; }

  // ---- plans: strips of states, toolpaths ---------------------------------------------------
  const stateMeshes = [];  // [plan][action] -> mesh data
  let shownState = null, shownPath = null;

  function toolpathObject(t) {
    const pos = new Float32Array(bytes(t.p).buffer), kinds = bytes(t.k), lay = new Uint16Array(bytes(t.l).buffer);
    const kindsOf = { rapid: 0, feed: 1, process: 2 };
    const group = new THREE.Group();
    const parts = {};
    for (const [kind, code] of Object.entries(kindsOf)) {
      const idx = [];
      for (let s = 0; s < kinds.length; ++s) if (kinds[s] === code) idx.push(s);
      const p = new Float32Array(idx.length * 6), l = new Uint16Array(idx.length);
      idx.forEach((s, j) => { p.set(pos.subarray(s * 6, s * 6 + 6), j * 6); l[j] = lay[s]; });
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(p, 3));
      const colour = kind === 'rapid' ? kColours.rapid : kind === 'feed' ? kColours.feed : t.additive ? kColours.deposit : kColours.cut;
      const material = kind === 'rapid'
        ? new THREE.LineDashedMaterial({ color: colour, dashSize: 2, gapSize: 1.5 })
        : new THREE.LineBasicMaterial({ color: colour, transparent: kind === 'feed', opacity: kind === 'feed' ? 0.6 : 1 });
      const lines = new THREE.LineSegments(g, material);
      if (kind === 'rapid') lines.computeLineDistances();
      parts[kind] = { lines: lines, layers: l };
      group.add(lines);
    }
    // The layer being looked at, drawn over the rest.
    const current = new THREE.LineSegments(new THREE.BufferGeometry(),
                                           new THREE.LineBasicMaterial({ color: kColours.current, depthTest: false }));
    current.renderOrder = 10;
    current.frustumCulled = false;  // its positions change with the slider
    group.add(current);
    group.userData = { parts: parts, current: current, positions: pos, kinds: kinds, layers: lay, info: 'toolpath' };
    return group;
  }

  // Shows the moves up to `layer` (all layers before it and that one), and that layer's
  // process moves in black on top.
  function setLayer(layer) {
    if (!shownPath) return;
    const u = shownPath.object.userData;
    for (const part of Object.values(u.parts)) {
      let n = 0;
      while (n < part.layers.length && part.layers[n] <= layer) ++n;
      part.lines.geometry.setDrawRange(0, n * 2);
    }
    const sel = [];
    for (let s = 0; s < u.kinds.length; ++s)
      if (u.kinds[s] === 2 && u.layers[s] === layer) for (let k = 0; k < 6; ++k) sel.push(u.positions[s * 6 + k]);
    u.current.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(sel), 3));
    report.layer = layer;
    const t = shownPath.toolpath, z = t.layer_z[layer];
    document.getElementById('layer-slider').value = layer;
    document.getElementById('layer-label').textContent =
      'Layer ' + (layer + 1) + ' of ' + t.layer_z.length + (typeof z === 'number' ? ' · Z ' + z.toFixed(2) + ' (setup ' + t.setup + ')' : '');
    requestRender();
  }

  function showState(planIndex, actionIndex) {
    const plan = data.plans[planIndex], action = plan.actions[actionIndex];
    if (shownState) { scene.remove(shownState); delete layers.state; }
    if (shownPath) { scene.remove(shownPath.object); delete layers.toolpath; }
    shownState = shownPath = null;
    const mode = action.mode === 'additive' ? 'additive' : 'subtractive';
    const m = meshOf(action.state, kColours[mode], 0.55);
    if (m) shownState = addLayer('state', m, true, 'plan ' + plan.rank + ' after action ' + (actionIndex + 1));
    const t = action.toolpath;
    const controlsBox = document.getElementById('path-controls');
    if (t && t.makes_gcode && t.segments > 0) {
      const object = toolpathObject(t);
      addLayer('toolpath', object, true, 'toolpath');
      shownPath = { object: object, toolpath: t };
      const slider = document.getElementById('layer-slider');
      slider.max = Math.max(0, t.layer_z.length - 1);
      controlsBox.hidden = false;
      document.getElementById('path-summary').textContent =
        (t.additive ? 'deposition' : 'milling') + ' with ' + t.instrument + ' · ' + t.segments + ' moves · motion ' + duration(t.cycle_s) +
        ' · ' + fmt(t.lengths.process, 0) + ' mm ' + (t.additive ? 'deposited' : 'cut') + ', ' + fmt(t.lengths.rapid, 0) + ' mm rapid';
      setLayer(t.layer_z.length - 1);
    } else {
      controlsBox.hidden = true;
      report.layer = null;
    }
    setVisible('design', false);
    hideExact();
    report.shown = { plan: planIndex, action: actionIndex };
    document.querySelectorAll('.state').forEach((e) =>
      e.classList.toggle('selected', Number(e.dataset.plan) === planIndex && Number(e.dataset.action) === actionIndex));
    setCaption('Plan ' + plan.rank + ' · after action ' + (actionIndex + 1) + ': ' + action.primitive + ' ' + (action.label || ''));
    legendEntries.splice(0, legendEntries.length, ...legendEntries.filter((e) => e[0] !== 'state' && e[0] !== 'toolpath'));
    legendEntries.push(['state', 'solid after the action', kColours[mode]]);
    if (shownPath) legendEntries.push(['toolpath', t.additive ? 'deposition' : 'cutting feed', t.additive ? kColours.deposit : kColours.cut],
                                      ['toolpath', 'feed, process off', kColours.feed], ['toolpath', 'rapid', kColours.rapid],
                                      ['toolpath', 'current layer', kColours.current]);
    updateLegend();
    requestRender();
  }

  function stateCard(plan, planIndex, action, a) {
    const card = el('div', 'state');
    card.dataset.plan = planIndex;
    card.dataset.action = a;
    const img = el('img');
    img.alt = 'solid after action ' + (a + 1);
    card.append(img);
    const mode = action.mode === 'additive' ? 'additive' : 'subtractive';
    card.append(el('div', 'title', (a + 1) + '. ' + action.primitive + ' '), el('div', 'mode-' + mode, mode + (action.kind ? ' · ' + action.kind : '')));
    const t = action.toolpath || {};
    const instrument = action.kind === 'raw-stock' ? 'stock ' + action.capability : (t.instrument || action.capability || '');
    const lines = [instrument + (action.setup ? ' · setup ' + action.setup : ''), 'volume ' + vol(action.volume),
                   'cost ' + fmt(action.cost, 4) + (typeof t.cycle_s === 'number' && t.makes_gcode ? ' · ' + duration(t.cycle_s) : '')];
    if (t.note && !t.makes_gcode) lines.push(t.note);
    for (const line of lines) card.append(el('div', 'facts', line));
    card.title = action.label || '';
    card.addEventListener('click', () => showState(planIndex, a));
    return card;
  }

  function buildPlans() {
    const box = document.getElementById('plans');
    const plans = data.plans || [];
    if (!plans.length) {
      box.append(el('div', '', 'No plan: ' + ((data.verdict && data.verdict.summary) || 'the part is not manufacturable with this machine.')));
      return;
    }
    plans.forEach((plan, k) => {
      const div = el('div', 'plan');
      const head = el('div', 'plan-head');
      head.append(el('h3', '', 'Plan ' + plan.rank), el('span', 'expr', plan.expression || ''));
      const dev = plan.deviation || {};
      const facts = ['cost ' + fmt(plan.cost, 4), (plan.cycle_time ? 'cycle time ' : 'motion ') + duration(plan.cycle_s) +
                     (plan.cycle_time && plan.cycle_time.includes ? ' (' + plan.cycle_time.includes.replace(/^[^:]*: /, '') + ')' : ''),
                     (plan.actions || []).length + ' actions',
                     'worst deviation on the voxels ' + fmt(dev.worst_distance, 2) + ' mm' + (dev.within_tolerance === false ? ' (beyond tolerance)' : '')];
      const exact = plan.exact_map && plan.exact_map.summary ? plan.exact_map.summary : dev.exact;
      if (exact) facts.push('exact: excess ' + fmt(exact.max_excess_mm, 3) + ' mm, gouge ' + fmt(exact.max_gouge_mm, 3) + ' mm' +
                            (exact.within_tolerance === false ? ' (beyond tolerance)' : ''));
      if (typeof plan.gap === 'number') facts.push('gap ' + fmt(plan.gap * 100, 1) + ' %');
      if (plan.optimal !== undefined) facts.push(plan.optimal ? 'proven optimal' : 'not proven optimal');
      if (plan.toolpath_error) facts.push('no toolpaths: ' + plan.toolpath_error);
      head.append(el('span', 'facts', facts.join(' · ')));
      if (plan.exact_map && !plan.exact_map.error && layers.exact) {
        const show = el('button', 'exact-plan', 'exact deviation on the design');
        show.dataset.plan = k;
        show.addEventListener('click', () => showExact(k));
        head.append(show);
      }
      div.append(head);
      const strip = el('div', 'strip');
      (plan.actions || []).forEach((action, a) => {
        if (a > 0) strip.append(el('div', 'arrow', '→'));
        strip.append(stateCard(plan, k, action, a));
      });
      div.append(strip);
      box.append(div);
    });
  }

  function buildRejected() {
    const rejected = data.rejected || [];
    if (!rejected.length) return;
    const panel = document.getElementById('rejected-panel');
    panel.hidden = false;
    const box = document.getElementById('rejected');
    rejected.forEach((r, i) => {
      const item = el('div', 'rejected');
      item.append(el('div', '', (r.expression || 'candidate ' + (i + 1)) + ' · cost ' + fmt(r.cost, 4)));
      (r.reasons || []).forEach((reason) => {
        const text = [reason.kind, reason.action !== undefined ? 'action ' + reason.action : '',
                      reason.line !== undefined ? 'line ' + reason.line : '', reason.message].filter(Boolean).join(' · ');
        const line = el('div', 'reason' + (reason.where ? ' placed' : ''), text + (reason.where ? ' at ' + xyz(reason.where) : ''));
        if (reason.where) line.addEventListener('click', () => place(reason.where, kColours.place, text));
        item.append(line);
      });
      box.append(item);
    });
  }

  // A marker at a place (an alarm, a rejection's reason), framed.
  function place(where, colour, info) {
    const size = Math.max(1.5, 3 * (data.voxel_size || 0.5));
    const marker = new THREE.Mesh(new THREE.SphereBufferGeometry(size, 16, 12), new THREE.MeshBasicMaterial({ color: colour, depthTest: false }));
    marker.renderOrder = 20;
    marker.position.set(where[0], where[1], where[2]);
    if (layers.marker) scene.remove(layers.marker);
    addLayer('marker', marker, true, info);
    const box = new THREE.Box3().setFromCenterAndSize(marker.position, new THREE.Vector3(30, 30, 30));
    frame(box, 1.2);
    setCaption(info);
  }

  // ---- after a dry run ------------------------------------------------------------------------
  function buildAsBuilt() {
    const b = data.as_built;
    if (!b) return;
    const panel = document.getElementById('as-built-panel');
    panel.hidden = false;
    panel.append(el('h2', '', 'As built (dry run)'));
    panel.append(el('div', 'note', 'What this run built, on the plan\'s voxels: it shows what the run did (an alarm that ' +
                    'stopped it, lines it did not execute) and volumes, and deviations deeper than exact verification\'s ' +
                    'vectors reach. How far the surface is from the design is measured to a voxel here; the exact ' +
                    'deviation above measures it on the STL itself.'));
    const list = el('div');
    panel.append(list);
    addLayer('as-built', meshOf(b.built, kColours.built, 0.5), false, 'as built\n' + vol(b.built_volume));
    toggle(list, 'as-built', 'as built', kColours.built, vol(b.built_volume));
    const labels = { over_within: 'beyond the design, within the band', over_beyond: 'beyond the design and the band',
                     under_within: 'missing, within the band', under_beyond: 'missing, deeper than the band' };
    // Over the exact map they would hide the facets it paints: shown at first only without one.
    const bandsShown = !exactMaps.some(Boolean);
    for (const [band, label] of Object.entries(labels)) {
      const entry = (b.bands || {})[band];
      if (!entry) continue;
      addLayer('deviation:' + band, meshOf(entry.mesh, kColours[band], 1), bandsShown, label + '\n' + vol(entry.volume));
      toggle(list, 'deviation:' + band, label, kColours[band], vol(entry.volume));
      legendEntries.push(['deviation:' + band, label, kColours[band]]);
    }
    if (b.run) {
      panel.append(el('div', 'numbers', 'run ended by ' + b.run.ended_by + ' · ' + b.run.lines_executed + ' lines · ' +
                                        duration(b.run.virtual_time_s) + ' machine time · ' + b.run.alarms + ' alarms'));
    }
    (b.alarms || []).forEach((a) => {
      const text = 'alarm ' + a.alarm + ' at line ' + a.line + (a.where ? ' ' + xyz(a.where) : '');
      const item = el('div', 'alarm', text);
      if (a.where) item.addEventListener('click', () => place(a.where, kColours.alarm, text));
      panel.append(item);
    });
  }

  // ---- exact deviation on the design's own mesh (report/report_exact.hpp) ----------------------
  // Each facet of the STL coloured by the worst of its samples for the plan shown: signed
  // (excess one way, gouge the other), beyond the tolerance in flat dark colours and outlined.
  const floats = (b64) => new Float32Array(bytes(b64).buffer);
  let exactShown = null;  // the plan index whose map is shown
  const exactMaps = [];   // per plan: decoded figures, or null
  function rgb(hex) { return [((hex >> 16) & 255) / 255, ((hex >> 8) & 255) / 255, (hex & 255) / 255]; }
  function exactColour(v, tol) {
    tol = tol > 0 ? tol : 1e-9;
    if (v > tol) return rgb(kExact.excessBeyond);
    if (v < -tol) return rgb(kExact.gougeBeyond);
    const a = rgb(kExact.neutral), b = rgb(v >= 0 ? kExact.excess : kExact.gouge), t = Math.min(1, Math.abs(v) / tol);
    return [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t];
  }
  function actionName(plan, a) {
    if (!a) return 'the start stock';
    const action = (plan.actions || [])[a - 1];
    return 'action ' + a + (action ? ' (' + action.primitive + ' ' + (action.label || '') + ')' : '');
  }
  function decodeExact(plan) {
    const m = plan.exact_map;
    if (!m || m.error || !m.excess) return null;
    return { excess: floats(m.excess), gouge: floats(m.gouge), action: new Uint16Array(bytes(m.action).buffer),
             deposited: bytes(m.deposited), summary: m.summary || {} };
  }
  // Line segments along the edges of the facets `pick` selects, from the non-indexed positions.
  function facetEdges(pos, count, pick) {
    const out = [];
    for (let t = 0; t < count; ++t) {
      if (!pick(t)) continue;
      for (let e = 0; e < 3; ++e) {
        const a = (t * 3 + e) * 3, b = (t * 3 + (e + 1) % 3) * 3;
        out.push(pos[a], pos[a + 1], pos[a + 2], pos[b], pos[b + 1], pos[b + 2]);
      }
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(out), 3));
    return g;
  }

  function buildExact() {
    const surface = (data.design || {}).surface;
    const plans = data.plans || [];
    if (!surface || !plans.length) return;
    const panel = document.getElementById('exact-panel');
    panel.hidden = false;
    panel.append(el('h2', '', 'Exact deviation on the design'));
    if (surface.error || !surface.mesh) {
      panel.append(el('div', 'note', 'No exact deviation map: ' + (surface.error || 'no mesh')));
      return;
    }
    plans.forEach((plan) => exactMaps.push(decodeExact(plan)));
    if (!exactMaps.some(Boolean)) {
      panel.append(el('div', 'note', 'No plan could be replayed: ' + plans.map((p) => 'plan ' + p.rank + ': ' +
                                     ((p.exact_map && p.exact_map.error) || 'not measured')).join('; ')));
      return;
    }
    const g = decodeMesh(surface.mesh).toNonIndexed();
    const count = surface.triangles;
    g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(count * 9), 3));
    const material = new THREE.MeshPhongMaterial({
      vertexColors: THREE.VertexColors !== undefined ? THREE.VertexColors : true, flatShading: true, side: THREE.DoubleSide,
      shininess: 20, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    const mesh = new THREE.Mesh(g, material);
    mesh.userData.faceInfo = (t) => {
      const m = exactMaps[exactShown], plan = plans[exactShown];
      if (!m) return 'design (' + surface.file + ')';
      return 'plan ' + plan.rank + ', facet ' + t + ' of ' + surface.file + '\nexcess ' + fmt(m.excess[t], 3) + ' mm, gouge ' +
             fmt(m.gouge[t], 3) + ' mm (worst of its samples)\nleft by ' + actionName(plan, m.action[t]) +
             (m.deposited[t] ? '\nleft as deposited' : '');
    };
    addLayer('exact', mesh, false, 'exact deviation');
    const none = () => facetEdges(new Float32Array(0), 0, () => false);
    addLayer('exact:beyond', new THREE.LineSegments(none(), new THREE.LineBasicMaterial({ color: kExact.outline })),
             false, 'facets beyond the tolerance');
    addLayer('exact:deposited', new THREE.LineSegments(none(),
                                                      new THREE.LineDashedMaterial({ color: kExact.deposited, dashSize: 1.2, gapSize: 0.8 })),
             false, 'facets left as deposited');
    addLayer('exact:worst', new THREE.Group(), false, 'largest excess and deepest gouge');
    const list = document.getElementById('layers');
    list.append(el('div', 'group', 'Exact deviation'));
    toggle(list, 'exact', 'the design\'s mesh (' + surface.file + '), coloured', kExact.excess, count + ' facets');
    toggle(list, 'exact:beyond', 'outline: beyond the tolerance', kExact.outline);
    toggle(list, 'exact:deposited', 'dashed: left as deposited', kExact.deposited);
    toggle(list, 'exact:worst', 'markers: largest excess, deepest gouge', kExact.excessBeyond);

    panel.append(el('div', 'note', surface.file + ', ' + count + ' facets: each coloured by the worst of its samples ' +
                    'for the plan chosen (its program replayed from its start stock as validation runs it, the part it ' +
                    'makes measured against the STL by exact verification). Hover a facet for its figures.'));
    const buttons = el('div', 'exact-plans');
    plans.forEach((plan, k) => {
      const b = el('button', 'exact-plan', 'Plan ' + plan.rank);
      b.dataset.plan = k;
      if (!exactMaps[k]) { b.disabled = true; b.title = (plan.exact_map && plan.exact_map.error) || 'not measured'; }
      b.addEventListener('click', () => showExact(k));
      buttons.append(b);
    });
    panel.append(buttons);
    const tol = data.tolerance;
    const stops = [[0, kExact.gougeBeyond], [14, kExact.gougeBeyond], [14, kExact.gouge], [50, kExact.neutral], [86, kExact.excess],
                   [86, kExact.excessBeyond], [100, kExact.excessBeyond]];
    const scale = el('div', 'exact-scale');
    scale.style.background = 'linear-gradient(to right, ' +
      stops.map(([at, c]) => '#' + c.toString(16).padStart(6, '0') + ' ' + at + '%').join(', ') + ')';
    const labels = el('div', 'exact-scale-labels');
    for (const text of ['gouge > ' + fmt(tol, 2), '−' + fmt(tol, 2), '0', '+' + fmt(tol, 2), 'excess > ' + fmt(tol, 2) + ' mm'])
      labels.append(el('span', '', text));
    panel.append(scale, labels);
    const figures = el('div');
    figures.id = 'exact-figures';
    panel.append(figures);
  }

  function hideExact() {
    for (const name of ['exact', 'exact:beyond', 'exact:deposited', 'exact:worst']) setVisible(name, false);
    document.querySelectorAll('.exact-plan').forEach((b) => b.classList.remove('selected'));
  }

  function showExact(k) {
    const m = exactMaps[k], plan = data.plans[k], surface = data.design.surface;
    if (!m || !layers.exact) return;
    if (shownState) { scene.remove(shownState); delete layers.state; }
    if (shownPath) { scene.remove(shownPath.object); delete layers.toolpath; }
    shownState = shownPath = null;
    document.getElementById('path-controls').hidden = true;
    report.layer = null;
    report.shown = null;
    document.querySelectorAll('.state').forEach((e) => e.classList.remove('selected'));
    exactShown = k;
    report.exactPlan = k;
    const tol = data.tolerance, count = surface.triangles;
    const g = layers.exact.geometry, colours = g.getAttribute('color');
    for (let t = 0; t < count; ++t) {
      const v = m.excess[t] >= m.gouge[t] ? m.excess[t] : -m.gouge[t], c = exactColour(v, tol);
      for (let j = 0; j < 3; ++j) colours.setXYZ(t * 3 + j, c[0], c[1], c[2]);
    }
    colours.needsUpdate = true;
    const pos = g.getAttribute('position').array;
    layers['exact:beyond'].geometry.dispose();
    layers['exact:beyond'].geometry = facetEdges(pos, count, (t) => m.excess[t] > tol || m.gouge[t] > tol);
    layers['exact:deposited'].geometry.dispose();
    layers['exact:deposited'].geometry = facetEdges(pos, count, (t) => m.deposited[t] > 0);
    layers['exact:deposited'].computeLineDistances();
    // The largest excess and the deepest gouge, marked where they are (seen through the part).
    const worst = layers['exact:worst'];
    worst.children.slice().forEach((c) => { worst.remove(c); c.traverse((o) => { if (o.geometry) o.geometry.dispose(); }); });
    const size = Math.max(0.8, 1.5 * (data.voxel_size || 0.5));
    for (const [p, colour, what] of [[m.summary.excess, kExact.excessBeyond, 'largest excess'], [m.summary.gouge, kExact.gougeBeyond, 'deepest gouge']]) {
      if (!p || !p.at || !(p.mm > 0)) continue;
      // A dot in the direction's colour in a white ring where it is in sight, and faint
      // where the part hides it (so that one behind the part is not taken for one on it).
      const marker = new THREE.Mesh(new THREE.SphereBufferGeometry(size, 16, 12),
                                    new THREE.MeshBasicMaterial({ color: colour, transparent: true, opacity: 1 }));
      marker.renderOrder = 16;  // after its ring, which leaves the depth as it was
      const ring = new THREE.Mesh(new THREE.SphereBufferGeometry(size * 1.6, 16, 12),
                                  new THREE.MeshBasicMaterial({ color: 0xffffff, transparent: true, opacity: 0.9, depthWrite: false }));
      ring.renderOrder = 15;
      const ghost = new THREE.Mesh(new THREE.SphereBufferGeometry(size * 1.6, 16, 12),
                                   new THREE.MeshBasicMaterial({ color: colour, depthTest: false, depthWrite: false,
                                                                 transparent: true, opacity: 0.3 }));
      ghost.renderOrder = 14;
      marker.add(ring, ghost);
      marker.position.set(p.at[0], p.at[1], p.at[2]);
      marker.userData.info = 'plan ' + plan.rank + ': ' + what + ' ' + fmt(p.mm, 3) + ' mm at ' + xyz(p.at) + '\nleft by ' +
                             actionName(plan, p.action) + (p.line ? ', line ' + p.line : '');
      worst.add(marker);
    }
    setVisible('design', false);
    for (const name of ['exact', 'exact:beyond', 'exact:deposited', 'exact:worst']) setVisible(name, true);
    document.querySelectorAll('.exact-plan').forEach((b) => b.classList.toggle('selected', Number(b.dataset.plan) === k));

    const box = document.getElementById('exact-figures');
    box.textContent = '';
    const s = m.summary;
    const figure = (what, p, colour) => {
      if (!p) return;
      const beyond = p.mm > tol;
      const text = what + ' ' + (p.at_least ? 'at least ' : '') + fmt(p.mm, 3) + ' mm' + (p.at ? ' at ' + xyz(p.at) : '') +
                   (p.at ? ', left by ' + actionName(plan, p.action) + (p.line ? ', line ' + p.line : '') : '') +
                   (p.as_deposited ? ', as deposited' : '') + (beyond ? ' · beyond the tolerance' : '');
      const item = el('div', 'exact-figure' + (p.at ? ' placed' : '') + (beyond ? ' beyond' : ''), text);
      item.style.borderLeftColor = '#' + colour.toString(16).padStart(6, '0');
      if (p.at) item.addEventListener('click', () => place(p.at, colour, 'Plan ' + plan.rank + ': ' + text));
      box.append(item);
    };
    box.append(el('h3', '', 'Plan ' + plan.rank + ': ' + (s.within_tolerance ? 'within' : 'OUTSIDE') + ' the tolerance of ' +
                            fmt(tol, 2) + ' mm'));
    figure('Largest excess', s.excess, s.excess && s.excess.mm > tol ? kExact.excessBeyond : kExact.excess);
    figure('Deepest gouge', s.gouge, s.gouge && s.gouge.mm > tol ? kExact.gougeBeyond : kExact.gouge);
    const map = plan.exact_map;
    box.append(el('div', 'numbers', fmt(100 * s.within_share, 1) + ' % of the surface within the tolerance both ways · ' +
                                    map.beyond_triangles + ' facets beyond it (outlined) · ' + map.deposited_triangles +
                                    ' left as deposited (dashed) · ' + s.samples + ' samples ' + fmt(s.spacing, 2) + ' mm apart'));
    setCaption('Plan ' + plan.rank + ' · exact deviation on the design\'s mesh (' + surface.file + ')');
    legendEntries.splice(0, legendEntries.length, ...legendEntries.filter((e) => !e[0].startsWith('exact')));
    legendEntries.push(['exact', 'excess beyond ' + fmt(tol, 2) + ' mm', kExact.excessBeyond],
                       ['exact', 'excess', kExact.excess], ['exact', 'on the design', kExact.neutral],
                       ['exact', 'gouge', kExact.gouge], ['exact', 'gouge beyond ' + fmt(tol, 2) + ' mm', kExact.gougeBeyond]);
    if (map.beyond_triangles > 0) legendEntries.push(['exact:beyond', 'outlined: beyond the tolerance', kExact.outline]);
    if (map.deposited_triangles > 0) legendEntries.push(['exact:deposited', 'left as deposited', kExact.deposited]);
    updateLegend();
    requestRender();
  }

  // ---- hover -------------------------------------------------------------------------------
  const raycaster = new THREE.Raycaster();
  const tooltip = document.getElementById('tooltip');
  canvas.addEventListener('mousemove', (event) => {
    const r = canvas.getBoundingClientRect();
    const mouse = new THREE.Vector2(((event.clientX - r.left) / r.width) * 2 - 1, -((event.clientY - r.top) / r.height) * 2 + 1);
    raycaster.setFromCamera(mouse, camera);
    const candidates = [];
    scene.traverseVisible((o) => { if (o.isMesh) candidates.push(o); });
    const hit = raycaster.intersectObjects(candidates, false)[0];
    if (!hit) { tooltip.hidden = true; return; }
    let o = hit.object, info = o.userData.faceInfo && hit.faceIndex !== undefined && hit.faceIndex !== null
      ? o.userData.faceInfo(hit.faceIndex) : o.userData.info;
    while (!info && o.parent) { o = o.parent; info = o.userData.info; }
    const p = hit.point;
    tooltip.textContent = (info || o.name) + '\nat ' + xyz([p.x, p.y, p.z]);
    tooltip.style.left = (event.clientX - r.left + 14) + 'px';
    tooltip.style.top = (event.clientY - r.top + 14) + 'px';
    tooltip.hidden = false;
  });
  canvas.addEventListener('mouseleave', () => { tooltip.hidden = true; });

  // ---- thumbnails of the states, drawn after the page is up -----------------------------------
  function drawThumbnails() {
    const cards = Array.from(document.querySelectorAll('.state'));
    if (!cards.length) return Promise.resolve();
    const small = document.createElement('canvas');
    small.width = 372;
    small.height = 264;
    const r = new THREE.WebGLRenderer({ canvas: small, antialias: true, preserveDrawingBuffer: true });
    r.setClearColor(0xf5f7fa, 1);
    const s = new THREE.Scene();
    const cam = new THREE.PerspectiveCamera(35, small.width / small.height, 0.1, 10000);
    cam.up.set(0, 0, 1);
    s.add(new THREE.AmbientLight(0xffffff, 0.5));
    const light = new THREE.DirectionalLight(0xffffff, 0.65);
    light.position.set(0.4, 0.8, 0.5);
    cam.add(light);
    s.add(cam);
    const box = layers.design ? new THREE.Box3().setFromObject(layers.design) : new THREE.Box3();
    return new Promise((resolve) => {
      let i = 0;
      function next() {
        if (i >= cards.length) { r.dispose(); resolve(); return; }
        const card = cards[i++];
        const action = data.plans[Number(card.dataset.plan)].actions[Number(card.dataset.action)];
        const mode = action.mode === 'additive' ? 'additive' : 'subtractive';
        const m = meshOf(action.state, kColours[mode], 1);
        if (m) {
          s.add(m);
          const b = box.isEmpty() ? new THREE.Box3().setFromObject(m) : box.clone().union(new THREE.Box3().setFromObject(m));
          const c = b.getCenter(new THREE.Vector3()), radius = b.getSize(new THREE.Vector3()).length() / 2;
          cam.position.copy(c).addScaledVector(kViewDirection, radius / Math.sin(degToRad(cam.fov / 2)) * 0.95);
          cam.lookAt(c);
          r.render(s, cam);
          card.querySelector('img').src = small.toDataURL('image/png');
          s.remove(m);
          m.geometry.dispose();
        }
        setTimeout(next, 0);
      }
      next();
    });
  }

  // ---- start ---------------------------------------------------------------------------------
  function start() {
    buildHeader();
    buildModel();
    buildVerdict();
    buildExact();
    buildPlans();
    buildRejected();
    buildAsBuilt();
    document.getElementById('layer-slider').addEventListener('input', (e) => setLayer(Number(e.target.value)));
    document.getElementById('footer').textContent = 'hybridctl report · three.js r' + THREE.REVISION +
      ' · meshes within ' + (data.budget ? data.budget.design + ' (design) / ' + data.budget.state + ' (each state)' : '?') + ' triangles';
    resize();
    const all = new THREE.Box3();
    for (const name of ['design', 'violating']) if (layers[name]) all.union(new THREE.Box3().setFromObject(layers[name]));
    frame(all);
    setCaption((data.verdict && (data.verdict.outcome || (data.verdict.manufacturable ? 'manufacturable' : '')) === 'manufacturable') ? 'Design' : 'Design and its offending atoms');
    updateLegend();
    // A part with plans opens on the best plan's exact deviation on the design's mesh.
    const first = exactMaps.findIndex(Boolean);
    if (first >= 0) showExact(first);
    renderer.render(scene, camera);
    drawThumbnails().then(() => { report.ready = true; requestRender(); });
  }
  window.addEventListener('error', (e) => report.errors.push(String(e.message)));
  try {
    start();
  } catch (e) {
    report.errors.push(String(e && e.stack || e));
    throw e;
  }
  // Where a layer's bounding box lands in the view, in CSS pixels of the page: [left, top,
  // right, bottom]. The browser test looks for the part's pixels there.
  report.screenBoxOf = function (name) {
    const o = layers[name];
    if (!o) return null;
    const box = new THREE.Box3().setFromObject(o), r = canvas.getBoundingClientRect();
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    for (let c = 0; c < 8; ++c) {
      const p = new THREE.Vector3(c & 1 ? box.max.x : box.min.x, c & 2 ? box.max.y : box.min.y, c & 4 ? box.max.z : box.min.z).project(camera);
      const x = r.left + (p.x + 1) / 2 * r.width, y = r.top + (1 - p.y) / 2 * r.height;
      x0 = Math.min(x0, x); y0 = Math.min(y0, y); x1 = Math.max(x1, x); y1 = Math.max(y1, y);
    }
    return [Math.max(r.left, x0), Math.max(r.top, y0), Math.min(r.right, x1), Math.min(r.bottom, y1)];
  };
  report.setVisible = setVisible;
  report.frameAtom = frameAtom;
  report.showState = showState;
  report.showExact = showExact;
  report.setLayer = setLayer;
})();
