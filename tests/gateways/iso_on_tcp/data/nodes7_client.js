// nodes7 0.3.18, unmodified, against the pbvbus ISO-on-TCP door (tests/gateways/iso_on_tcp/
// nodes7_client_test.cpp). Usage: NODE_PATH=<dir with nodes7> node nodes7_client.js PORT
// Prints one `key=value` line per result, then `done`, and exits; the test checks the lines and
// the CPU's memory.
'use strict';
const nodes7 = require('nodes7');

const port = parseInt(process.argv[2], 10);
const conn = new nodes7({ silent: true });
const out = (k, v) => process.stdout.write(k + '=' + JSON.stringify(v) + '\n');

function fail(why) {
  out('error', why);
  process.exit(1);
}

function read(items) {
  return new Promise((resolve) => {
    conn.removeItems();
    conn.addItems(items);
    conn.readAllItems((anythingBad, values) => resolve({ anythingBad, values }));
  });
}

function write(items, values) {
  return new Promise((resolve) => {
    conn.writeItems(items, values, (anythingBad) => resolve(anythingBad));
  });
}

async function run() {
  // One readAllItems over six areas: nodes7 puts them into one multi-item Read Var.
  const multi = await read(['DB1,B0.4', 'DB1,INT4', 'DB1,REAL8', 'DB1,WORD12', 'MB10', 'IB0', 'QB0',
                            'M11.1', 'C5', 'T3']);
  out('multi_bad', multi.anythingBad);
  for (const k of Object.keys(multi.values)) out(k, multi.values[k]);

  const writeBad = await write(['DB1,B20', 'DB1,INT22', 'DB1,REAL24', 'MB20', 'QB1', 'DB1,WORD28'],
                               [0x5A, -1234, 3.5, 7, 0x81, 0xBEEF]);
  out('write_bad', writeBad);

  const back = await read(['DB1,B20', 'DB1,INT22', 'DB1,REAL24', 'MB20', 'QB1', 'DB1,WORD28']);
  out('back_bad', back.anythingBad);
  for (const k of Object.keys(back.values)) out('back ' + k, back.values[k]);

  const missing = await read(['DB9,B0']);
  out('missing_bad', missing.anythingBad);
  out('missing DB9,B0', missing.values['DB9,B0']);

  conn.dropConnection(() => {
    out('done', true);
    process.exit(0);
  });
}

conn.initiateConnection({ host: '127.0.0.1', port, rack: 0, slot: 2, timeout: 8000 }, (err) => {
  if (typeof err !== 'undefined') fail(String(err));
  run().catch((e) => fail(String(e)));
});
setTimeout(() => fail('no result within 30 s'), 30000).unref();
