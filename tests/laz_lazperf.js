// laz_lazperf.js -- decode a LAZ file with laz-perf (the npm package: LASzip's
// format compiled to WebAssembly, an implementation independent of ours) and
// print its points' integer coordinates, one "X Y Z" line per point in file
// order, after a first line "count N"; with `field [F]`, each line also
// gets the record's last 8 * F bytes (F = 1 when not given) as F
// little-endian 64-bit integers in hexadecimal (the values hd_write_fields
// added, in order); with `record`, each line is the whole record in
// hexadecimal, byte by byte, instead.
//
//   node laz_lazperf.js NODE_MODULES_DIR FILE.laz [field [F] | record]
//
// tests/laz_lazperf.py runs it on the files the tests' LAZ writer makes and
// compares with the points the writer was given.
'use strict';
const fs = require('fs');
const path = require('path');
const [modules, file, field, nfields] = process.argv.slice(2);
const nf = nfields ? parseInt(nfields, 10) : 1;
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
      for (let j = 0; j < nf; j++) {
        const end = len - 8 * (nf - j);
        let hex = '';
        for (let b = end + 7; b >= end; b--) hex += v.getUint8(b).toString(16).padStart(2, '0');
        line += ' ' + hex;
      }
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
