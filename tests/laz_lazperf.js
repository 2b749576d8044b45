// laz_lazperf.js -- decode a LAZ file with laz-perf (the npm package: LASzip's
// format compiled to WebAssembly, an implementation independent of ours) and
// print its points' integer coordinates, one "X Y Z" line per point in file
// order, after a first line "count N"; with `field`, each line also gets
// the record's last eight bytes as a little-endian 64-bit integer in
// hexadecimal (the value hd_write_field added); with `record`, each line is
// the whole record in hexadecimal, byte by byte, instead.
//
//   node laz_lazperf.js NODE_MODULES_DIR FILE.laz [field | record]
//
// tests/laz_lazperf.py runs it on the files the tests' LAZ writer makes and
// compares with the points the writer was given.
'use strict';
const fs = require('fs');
const path = require('path');
const [modules, file, field] = process.argv.slice(2);
const { createLazPerf } = require(path.resolve(modules, 'laz-perf'));

(async () => {
  const lp = await createLazPerf();
  const data = fs.readFileSync(file);
  const fp = lp._malloc(data.length);
  lp.HEAPU8.set(data, fp);
  const laz = new lp.LASZip();
  laz.open(fp, data.length);
  const n = laz.getCount(), len = laz.getPointLength();
  const pp = lp._malloc(len);
  const out = ['count ' + n];
  for (let i = 0; i < n; i++) {
    laz.getPoint(pp);
    const v = new DataView(lp.HEAPU8.buffer, pp, len);
    let line = v.getInt32(0, true) + ' ' + v.getInt32(4, true) + ' ' + v.getInt32(8, true);
    if (field === 'record') {
      line = '';
      for (let b = 0; b < len; b++) line += v.getUint8(b).toString(16).padStart(2, '0');
    }
    if (field === 'field') {
      let hex = '';
      for (let b = len - 1; b >= len - 8; b--) hex += v.getUint8(b).toString(16).padStart(2, '0');
      line += ' ' + hex;
    }
    out.push(line);
  }
  process.stdout.write(out.join('\n') + '\n');
  laz.delete();
  lp._free(pp);
  lp._free(fp);
})().catch((e) => {
  console.error('laz_lazperf.js: ' + file + ': ' + e);
  process.exit(1);
});
