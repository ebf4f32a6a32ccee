'use strict'
// Benchmark (not a test): chunk streaming of a release `infiniterra serve`.
//
//   cargo build --release
//   npm ci --prefix tests/e2e            # once
//   node tests/e2e/bench_fly.js [--seed N] [--view 10] [--speed 67] [--seconds 25] [--threads 2]
//                               [--binary target/release/infiniterra]
//
// Run from the repository root. It starts target/release/infiniterra on a free loopback port
// with a temporary config (view_distance_cap = --view, chunk_threads = --threads, the default
// chunk cache) and the rules in biomes/, then, one player after another:
//   1. cold join: time from connecting until every chunk of the view has arrived (nothing
//      built yet);
//   2. warm join: the same, once the first player has left (its chunks are in the cache);
//   3. flight: a player flies along +x at --speed blocks/s (elytra ≈ 67) for --seconds; chunks
//      per second received during the flight, how many positions of the view were missing on
//      average and at worst, how many positions entered and left the view without arriving,
//      and how long after arriving the last chunks of the final view took.
// Prints a JSON summary on stdout; the server's `status` at the end is included.

const { spawn } = require('child_process')
const fs = require('fs')
const net = require('net')
const os = require('os')
const path = require('path')
const readline = require('readline')
const { fly } = require('./fly.js')

function parseArgs (argv) {
  const args = { seed: 1, view: 10, speed: 67, seconds: 25, threads: 2, binary: null }
  for (let i = 0; i < argv.length; i += 2) {
    const key = argv[i].replace(/^--/, '')
    if (!(key in args)) throw new Error(`unknown argument ${argv[i]}`)
    args[key] = key === 'binary' ? argv[i + 1] : Number(argv[i + 1])
  }
  return args
}

function freePort () {
  return new Promise((resolve, reject) => {
    const server = net.createServer()
    server.once('error', reject)
    server.listen(0, '127.0.0.1', () => {
      const { port } = server.address()
      server.close(() => resolve(port))
    })
  })
}

// The server's stdout, kept so that a line printed before anyone waits for it is not lost.
function lineQueue (input) {
  const lines = []
  const waiters = []
  readline.createInterface({ input }).on('line', line => {
    lines.push(line)
    for (const w of waiters.splice(0)) w()
  })
  let next = 0
  // Resolves with the next line matching `want` (rejects after `ms`).
  return (want, ms) => new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`no line matching ${want} in ${ms} ms`)), ms)
    const scan = () => {
      while (next < lines.length) {
        const line = lines[next++]
        if (want.test(line)) {
          clearTimeout(timer)
          return resolve(line)
        }
      }
      waiters.push(scan)
    }
    scan()
  })
}

async function main () {
  const args = parseArgs(process.argv.slice(2))
  const root = path.resolve(__dirname, '..', '..')
  const binary = args.binary ? path.resolve(args.binary) : path.join(root, 'target', 'release', 'infiniterra')
  if (!fs.existsSync(binary)) throw new Error(`${binary} is missing: run cargo build --release first`)
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'infiniterra-bench-'))
  const port = await freePort()
  const config = path.join(dir, 'server.toml')
  fs.writeFileSync(config, `[server]\nbind = "127.0.0.1:${port}"\nview_distance_cap = ${args.view}\n` +
    `chunk_threads = ${args.threads}\n\n[world]\nseed = ${args.seed}\n`)
  const server = spawn(binary, ['serve', '--config', config, '--biomes', path.join(root, 'biomes')],
    { cwd: root, stdio: ['pipe', 'pipe', 'inherit'], env: { ...process.env, RUST_LOG: 'warn' } })
  const nextLine = lineQueue(server.stdout)
  const summary = { binary, seed: args.seed, view: args.view, threads: args.threads, speed: args.speed, seconds: args.seconds }
  try {
    await nextLine(/listening on/, 300000)
    const timeout = args.seconds + 120
    const cold = await fly({ port, name: 'cold', view: args.view, cap: args.view, distance: 0, speed: 1, timeout })
    if (!cold.ok) throw new Error(`cold join: ${JSON.stringify(cold)}`)
    await nextLine(/^cold left$/, 30000)
    const warm = await fly({ port, name: 'warm', view: args.view, cap: args.view, distance: 0, speed: 1, timeout })
    if (!warm.ok) throw new Error(`warm join: ${JSON.stringify(warm)}`)
    await nextLine(/^warm left$/, 30000)
    summary.cold_join_all_chunks_ms = cold.first_view_ms
    summary.warm_join_all_chunks_ms = warm.first_view_ms
    summary.chunks_in_view = cold.final_view

    const distance = args.speed * args.seconds
    // Start the flight away from the spawn's warm chunks: fly from the spawn as it is.
    const f = await fly({ port, name: 'flyer', view: args.view, cap: args.view, distance, speed: args.speed, timeout })
    if (!f.ok) throw new Error(`flight: ${JSON.stringify(f)}`)
    summary.flight = {
      blocks: distance,
      seconds: f.flight_ms / 1000,
      chunks_received: f.flight_packets,
      chunks_per_second: f.flight_packets / (f.flight_ms / 1000),
      missing_in_view_mean: f.missing_in_flight_mean,
      missing_in_view_max: f.missing_in_flight_max,
      skipped_positions: f.skipped_in_flight,
      missing_on_arrival: f.missing_on_arrival,
      final_view_complete_after_ms: f.settle_ms
    }
    await nextLine(/^flyer left$/, 30000)
    server.stdin.write('status\n')
    summary.status = [
      await nextLine(/^chunks:/, 30000),
      await nextLine(/^queue:/, 30000),
      await nextLine(/^memory:/, 30000)
    ]
  } finally {
    server.stdin.write('stop\n')
    server.stdin.end()
    await new Promise(resolve => server.once('exit', resolve))
  }
  process.stdout.write(JSON.stringify(summary, null, 2) + '\n')
}

main().catch(error => {
  console.error(String(error && error.stack ? error.stack : error))
  process.exit(1)
})
