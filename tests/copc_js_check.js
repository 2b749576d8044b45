// An outside check of a COPC file written back (by hand, not in make test: it needs npm):
// copc.js (npm "copc" 0.0.8, over laz-perf) walks both files' hierarchies and reads every node;
// the output's node has the input node's points (X, Y, Z, Intensity, GpsTime) and, given DIST, the
// distances of the --distances table (one a line, in A's file order: nodes ordered by offset);
// with "farther D" / "nearer D" after DIST, only the points of each node with distance > D / <= D.
//   npm install --prefix SCRATCH copc@0.0.8
//   hausdorff --directed --distances out.copc.laz in.copc.laz b.laz
//   hausdorff --directed --distances d.csv in.copc.laz b.laz && awk -F, 'NR>1{print $4}' d.csv > d.txt
//   NODE_PATH=SCRATCH/node_modules node tests/copc_js_check.js in.copc.laz out.copc.laz d.txt
//   hausdorff --directed --farther-than 1 far.copc.laz in.copc.laz b.laz
//   NODE_PATH=SCRATCH/node_modules node tests/copc_js_check.js in.copc.laz far.copc.laz d.txt farther 1
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
function fileOrder(all) { // each node's first point in file order (nodes ordered by offset)
  const keys = Object.keys(all).filter(k => all[k].pointCount > 0);
  keys.sort((a, b) => all[a].pointDataOffset - all[b].pointDataOffset);
  const first = {}; let f = 0;
  for (const k of keys) { first[k] = f; f += all[k].pointCount; }
  return first;
}
(async () => {
  const [inp, out, dist, keep, D] = process.argv.slice(2);
  const d = dist ? fs.readFileSync(dist, 'utf8').trim().split('\n').map(Number) : null;
  const kept = x => keep === 'farther' ? x > Number(D) : keep === 'nearer' ? x <= Number(D) : true;
  const A = await nodes(inp), B = await nodes(out);
  const firstA = fileOrder(A.all);
  let pts = 0, bad = 0, n = 0;
  for (const k of Object.keys(A.all).filter(k => A.all[k].pointCount > 0)) {
    const a = A.all[k], b = B.all[k];
    const va = await Copc.loadPointDataView(inp, A.copc, a);
    const want = [];
    for (let i = 0; i < a.pointCount; i++) if (!d || kept(d[firstA[k] + i])) want.push(i);
    const bn = b ? b.pointCount : 0;
    if (bn !== want.length) throw new Error(`node ${k}: ${bn} points, ${want.length} expected`);
    if (!bn) continue;
    const vb = await Copc.loadPointDataView(out, B.copc, b);
    const g = ['X', 'Y', 'Z', 'Intensity', 'GpsTime'].map(n => [va.getter(n), vb.getter(n)]);
    const dd = vb.getter('distance');
    want.forEach((i, j) => {
      for (const [x, y] of g) if (x(i) !== y(j)) bad++;
      if (d && dd(j) !== d[firstA[k] + i]) bad++;
    });
    pts += bn, n++;
  }
  if (pts !== Number(B.copc.header.pointCount)) throw new Error(`nodes hold ${pts} points, the header ${B.copc.header.pointCount}`);
  console.log(`${out}: copc.js read ${n} nodes, ${pts} points; ${bad} mismatches`);
  process.exit(bad ? 1 : 0);
})().catch(e => { console.error('FAIL', e.message); process.exit(1); });
