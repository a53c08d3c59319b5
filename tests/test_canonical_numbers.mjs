// test_canonical_numbers.mjs: io/canonical's numbers (util/dtoa) against ECMAScript itself.
//
//   node tests/test_canonical_numbers.mjs build/tests/test_canonical
//
// Runs `test_canonical --dump`, which prints the unit test's deterministic stream of doubles as
// "family hex text" lines (hex: the IEEE 754 bits; text: prsm_canonical_number), compares every
// text with String(x) (Number::toString, which RFC 8785 §3.2.2.3 adopts), prints the first
// differences, and prints per family the count and the SHA-256 of node's "hex text\n" lines:
// the table family_expected of tests/test_canonical.c, so the unit test compares with node
// without needing node. Exit status 1 when any text differs.
import { spawnSync } from 'node:child_process';
import { createHash } from 'node:crypto';

const program = process.argv[2];
if (!program) {
  console.error('usage: node tests/test_canonical_numbers.mjs <path of the test_canonical program>');
  process.exit(2);
}
const run = spawnSync(program, ['--dump'], { maxBuffer: 1 << 30, encoding: 'utf8' });
if (run.status !== 0) {
  console.error(`${program} --dump failed (${run.status ?? run.signal}): ${run.stderr}`);
  process.exit(2);
}

const families = new Map(); // name -> {count, hash}
const bits = Buffer.alloc(8);
let total = 0, differ = 0;
for (const line of run.stdout.split('\n')) {
  if (!line) continue;
  const [family, hex, text] = line.split(' ');
  bits.write(hex, 'hex');
  const js = String(bits.readDoubleBE(0));
  if (js !== text) {
    if (differ < 20) console.log(`${family} ${hex}: prsm ${text}, node ${js}`);
    differ++;
  }
  let f = families.get(family);
  if (!f) families.set(family, (f = { count: 0, hash: createHash('sha256') }));
  f.count++;
  f.hash.update(`${hex} ${js}\n`);
  total++;
}
for (const [name, f] of families)
  console.log(`\t{${f.count}, "${f.hash.digest('hex')}"}, /* ${name} */`);
console.log(`${total} doubles, ${differ} differ from node ${process.version}'s String(x)`);
process.exit(differ ? 1 : 0);
