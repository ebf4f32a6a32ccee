'use strict'
// A creative player flies in a straight line along +x at a steady speed and reports which
// chunks reached it: whether every chunk of its final view arrived, how fast chunks came
// during the flight, and how long joining took until its whole first view was there.
// Driven by tests/server_e2e.rs; tests/e2e/bench_fly.js runs it at elytra speed.
//
// usage: node fly.js PORT [--name NAME] [--view CHUNKS] [--distance BLOCKS] [--speed BLOCKS_PER_S]
//                         [--cap CHUNKS] [--timeout SECONDS]
//
// --view is the view distance the client asks for; --cap the server's view_distance_cap: the
// view the bot expects is the smaller of the two.
// The bot does not run mineflayer's physics while flying (it stops simulating in chunks it
// has not received, which would let the server set the pace): it sends its own position
// every 50 ms, x = start + speed × elapsed, at the height it spawned at.
//
// Chunks are counted from the packets themselves: `map_chunk` loads a position, `unload_chunk`
// forgets it. The view is valence's: every chunk within view distance + 2 (Euclidean, in
// chunks) of the player's chunk. Prints one JSON line; exit code 0 with {"ok":true,...}, 1 with
// {"ok":false,"error":...}. Every wait is for a packet or a condition, bounded by the timeout.

const { createBot } = require('./bot')

function parseArgs (argv) {
  const args = { port: Number(argv[0]), name: 'flyer', view: 4, cap: 32, distance: 500, speed: 25, timeout: 120 }
  for (let i = 1; i < argv.length; i += 2) {
    const [key, value] = [argv[i], argv[i + 1]]
    if (key === '--name') args.name = value
    else if (key === '--view') args.view = Number(value)
    else if (key === '--cap') args.cap = Number(value)
    else if (key === '--distance') args.distance = Number(value)
    else if (key === '--speed') args.speed = Number(value)
    else if (key === '--timeout') args.timeout = Number(value)
    else throw new Error(`unknown argument ${key}`)
  }
  if (!Number.isInteger(args.port)) throw new Error('usage: node fly.js PORT [options]')
  return args
}

// valence's ChunkView: positions within dist + 2 chunks of the centre.
function view (cx, cz, dist) {
  const r = dist + 2
  const out = []
  for (let dz = -r; dz <= r; dz++) {
    for (let dx = -r; dx <= r; dx++) {
      if (dx * dx + dz * dz <= r * r) out.push(`${cx + dx},${cz + dz}`)
    }
  }
  return out
}

// Joins, flies, and resolves with the report (never rejects).
function fly (args) {
  return new Promise(resolve => {
    const started = Date.now()
    const bot = createBot(args.port, args.name, args.view)
    const dist = Math.min(args.view, args.cap)
    const report = { ok: false, name: args.name, view: dist }
    const loaded = new Set() // chunks the client holds now
    const everLoaded = new Set()
    let packets = 0
    // During the flight: each position of the view → whether it has been held while in view.
    const inView = new Map()
    let skipped = 0
    let missingSum = 0
    let missingMax = 0
    let steps = 0
    let flight = null // { t0, x0, y, z, timer, packetsAt0 }
    let done = false
    const finish = (ok, error) => {
      if (done) return
      done = true
      if (flight && flight.timer) clearInterval(flight.timer)
      report.ok = ok
      if (error) report.error = String(error)
      report.map_chunk_packets = packets
      try { bot.quit() } catch (_) {}
      // Give the quit packet a moment to leave, without waiting on the server.
      setTimeout(() => resolve(report), 200)
    }
    setTimeout(() => finish(false, `timed out after ${args.timeout} s`), args.timeout * 1000).unref()
    bot.on('kicked', reason => finish(false, `kicked: ${JSON.stringify(reason)}`))
    bot.on('error', error => finish(false, `error: ${error && error.message ? error.message : error}`))
    bot.on('end', reason => finish(false, `connection ended: ${reason}`))

    const centre = () => [Math.floor(bot.entity.position.x / 16), Math.floor(bot.entity.position.z / 16)]
    const missing = () => {
      const [cx, cz] = centre()
      return view(cx, cz, dist).filter(p => !loaded.has(p))
    }

    bot._client.on('map_chunk', p => {
      packets++
      loaded.add(`${p.x},${p.z}`)
      everLoaded.add(`${p.x},${p.z}`)
      if (inView.has(`${p.x},${p.z}`)) inView.set(`${p.x},${p.z}`, true)
      if (report.spawn_ms !== undefined && report.first_view_ms === undefined && missing().length === 0) {
        report.first_view_ms = Date.now() - started
        takeOff()
      }
    })
    bot._client.on('unload_chunk', p => loaded.delete(`${p.chunkX},${p.chunkZ}`))

    bot.once('spawn', () => {
      report.spawn_ms = Date.now() - started
      report.start = { x: bot.entity.position.x, y: bot.entity.position.y, z: bot.entity.position.z }
      if (missing().length === 0) {
        report.first_view_ms = Date.now() - started
        takeOff()
      }
    })

    function takeOff () {
      if (args.distance <= 0) return land()
      bot.physicsEnabled = false
      const p = bot.entity.position
      flight = { t0: Date.now(), x0: p.x, y: p.y, z: p.z, packetsAt0: packets }
      flight.timer = setInterval(step, 50)
    }

    function step () {
      const elapsed = (Date.now() - flight.t0) / 1000
      const x = Math.min(flight.x0 + args.speed * elapsed, flight.x0 + args.distance)
      bot.entity.position.x = x
      bot._client.write('position', { x, y: flight.y, z: flight.z, onGround: false })
      track()
      if (x >= flight.x0 + args.distance) {
        clearInterval(flight.timer)
        flight.timer = null
        report.flight_ms = Date.now() - flight.t0
        report.flight_packets = packets - flight.packetsAt0
        report.missing_on_arrival = missing().length
        report.missing_in_flight_mean = steps ? missingSum / steps : 0
        report.missing_in_flight_max = missingMax
        // Positions that came into view and left it again without ever arriving.
        report.skipped_in_flight = skipped
        land()
      }
    }

    // Which positions of the view the bot holds now, and which left the view never received.
    function track () {
      const [cx, cz] = centre()
      const now = new Set(view(cx, cz, dist))
      let gone = 0
      for (const p of now) {
        const held = loaded.has(p)
        if (!held) gone++
        inView.set(p, (inView.get(p) || false) || held)
      }
      for (const [p, got] of inView) {
        if (!now.has(p)) {
          if (!got) skipped++
          inView.delete(p)
        }
      }
      steps++
      missingSum += gone
      missingMax = Math.max(missingMax, gone)
    }

    // Hovering at the end: wait (bounded by the timeout) until every chunk of the view is held.
    function land () {
      const t = Date.now()
      const check = () => {
        if (done) return
        const gone = missing()
        if (gone.length === 0) {
          report.settle_ms = Date.now() - t
          report.final = { x: bot.entity.position.x, z: bot.entity.position.z, chunk: centre() }
          report.final_view = view(...centre(), dist).length
          report.loaded = loaded.size
          report.ever_loaded = everLoaded.size
          delete report.final_missing
          return finish(true)
        }
        report.final_missing = gone
      }
      // Re-checked whenever a chunk arrives; a poll at 20 Hz covers a view already complete.
      bot._client.on('map_chunk', check)
      const poll = setInterval(() => { if (done) clearInterval(poll); else check() }, 50)
      check()
    }
  })
}

module.exports = { fly, view }

if (require.main === module) {
  fly(parseArgs(process.argv.slice(2))).then(report => {
    process.stdout.write(JSON.stringify(report) + '\n')
    process.exit(report.ok ? 0 : 1)
  })
}
