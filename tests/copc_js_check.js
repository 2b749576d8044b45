// An outside check of a COPC file written back (by hand, not in make test: it needs npm):
// copc.js (npm "copc" 0.0.8, over laz-perf) walks both files' hierarchies and reads every node;
// the output's node has the input's points (X, Y, Z, Intensity, GpsTime) and, given DIST, the
// distances of the --distances table (one a line, in file order: nodes ordered by offset).
//   npm install --prefix SCRATCH copc@0.0.8
//   hausdorff --directed --distances out.copc.laz in.copc.laz b.laz
//   hausdorff --directed --distances d.csv in.copc.laz b.laz && awk -F, 'NR>1{print $4}' d.csv > d.txt
//   NODE_PATH=SCRATCH/node_modules node tests/copc_js_check.js in.copc.laz out.copc.laz d.txt
const { Copc } = require('copc');
const fs = require('fs');
async function nodes(file) {
  const copc = await Copc.create(file);
  const all = {};
  async function walk(page) {
    const sub = await Copc.loadHierarchyPage(file, page);
    Object.assign(all, sub.nodes);
    for (const p of Object.values(sub.pages)) await walk(p);
  }
  await walk(copc.info.rootHierarchyPage);
  return { copc, all };
}
(async () => {
  const [inp, out, dist] = process.argv.slice(2);
  const d = dist ? fs.readFileSync(dist, 'utf8').trim().split('\n').map(Number) : null;
  const A = await nodes(inp), B = await nodes(out);
  const keys = Object.keys(A.all).filter(k => A.all[k].pointCount > 0);
  const bkeys = Object.keys(B.all).filter(k => B.all[k].pointCount > 0);
  if (keys.length !== bkeys.length) throw new Error('node counts differ');
  // file order of the output's nodes: by offset
  const order = bkeys.slice().sort((a, b) => B.all[a].pointDataOffset - B.all[b].pointDataOffset);
  const firstOf = {}; let f = 0;
  for (const k of order) { firstOf[k] = f; f += B.all[k].pointCount; }
  let pts = 0, bad = 0;
  for (const k of keys) {
    const a = A.all[k], b = B.all[k];
    if (!b || a.pointCount !== b.pointCount) throw new Error('node ' + k + ' differs');
    const va = await Copc.loadPointDataView(inp, A.copc, a);
    const vb = await Copc.loadPointDataView(out, B.copc, b);
    const g = ['X', 'Y', 'Z', 'Intensity', 'GpsTime'].map(n => [va.getter(n), vb.getter(n)]);
    const dd = vb.getter('distance');
    for (let i = 0; i < a.pointCount; i++) {
      for (const [x, y] of g) if (x(i) !== y(i)) bad++;
      if (d && dd(i) !== d[firstOf[k] + i]) bad++;
    }
    pts += a.pointCount;
  }
  console.log(`${out}: copc.js read ${keys.length} nodes, ${pts} points (header ${B.copc.header.pointCount}); ${bad} mismatches`);
  process.exit(bad ? 1 : 0);
})().catch(e => { console.error('FAIL', e.message); process.exit(1); });
