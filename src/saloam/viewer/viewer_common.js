// What both viewer pages (viewer.html, live.html) share. Inlined by
// viewer_page.cpp before three.js, so that an error anywhere is reported.

// Errors are shown on the page and in its title (the headless tests read the title).
window.saloamErrors = [];
function saloamReportError(message) {
  window.saloamErrors.push(String(message));
  document.title = 'error: ' + window.saloamErrors.join(' | ');
  const box = document.getElementById('errors');
  if (box) { box.style.display = 'block'; box.textContent = window.saloamErrors.join('\n'); }
}
window.addEventListener('error', (e) => saloamReportError(e.message || e));
window.addEventListener('unhandledrejection', (e) => saloamReportError(e.reason));

const saloamPage = {
  base64Bytes(text) {
    const binary = atob(text);
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
    return bytes;
  },
  base64Floats(text) { return new Float32Array(saloamPage.base64Bytes(text).buffer); },

  escapeHtml(text) {
    return String(text).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[c]));
  },
  // A legend entry: a checkbox and its label (HTML).
  checkbox(labelHtml, checked, onChange) {
    const label = document.createElement('label');
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.checked = checked;
    box.addEventListener('change', () => onChange(box.checked));
    label.appendChild(box);
    label.insertAdjacentHTML('beforeend', labelHtml);
    return { label, box };
  },

  // The scene in the LiDAR frame (z up) on a canvas behind the panels, orbit
  // controls, and render(): one frame drawn at the next animation frame.
  createView(far) {
    const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setSize(window.innerWidth, window.innerHeight);
    renderer.setClearColor(0x101418);
    document.body.insertBefore(renderer.domElement, document.body.firstChild);
    const scene = new THREE.Scene();
    const camera = new THREE.PerspectiveCamera(55, window.innerWidth / window.innerHeight, 0.2, far);
    camera.up.set(0, 0, 1);
    const controls = new THREE.OrbitControls(camera, renderer.domElement);
    controls.screenSpacePanning = false;  // pan over the ground plane
    let queued = false;
    const render = () => {
      if (queued) return;
      queued = true;
      requestAnimationFrame(() => { queued = false; renderer.render(scene, camera); });
    };
    controls.addEventListener('change', render);
    return { renderer, scene, camera, controls, render };
  },

  // A loop edge as an arch over the map (the two poses of a revisit lie close
  // together): kArcSegments line segments from a to b, written into `out` at `offset`.
  kArcSegments: 12,
  loopArc(a, b, out, offset) {
    const height = 6 + 0.5 * a.distanceTo(b);
    const point = (t) => new THREE.Vector3().lerpVectors(a, b, t).setZ(a.z + (b.z - a.z) * t + height * 4 * t * (1 - t));
    for (let s = 0; s < saloamPage.kArcSegments; ++s) {
      point(s / saloamPage.kArcSegments).toArray(out, offset + 6 * s);
      point((s + 1) / saloamPage.kArcSegments).toArray(out, offset + 6 * s + 3);
    }
  },
};
