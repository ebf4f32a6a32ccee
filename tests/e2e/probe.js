'use strict'
// Joins an infiniterra server as a headless Minecraft 1.20.1 player (mineflayer) and prints
// what it saw as one JSON line on stdout. Driven by tests/server_e2e.rs.
//
// usage: node probe.js PORT [--name NAME] [--view CHUNKS] [--expect-chunks N]
//                           [--columns "x,z;x,z;..."] [--timeout SECONDS]
//
// Exit code 0 with {"ok":true,...}; 1 with {"ok":false,"error":...} on a kick, an error or
// the timeout. Every wait is for an event or a condition, bounded by the timeout.

const mineflayer = require('mineflayer')
const { Vec3 } = require('vec3')

function parseArgs (argv) {
  const args = { port: Number(argv[0]), name: 'probe', view: 4, expectChunks: 0, columns: [], timeout: 120 }
  for (let i = 1; i < argv.length; i += 2) {
    const [key, value] = [argv[i], argv[i + 1]]
    if (key === '--name') args.name = value
    else if (key === '--view') args.view = Number(value)
    else if (key === '--expect-chunks') args.expectChunks = Number(value)
    else if (key === '--timeout') args.timeout = Number(value)
    else if (key === '--columns') {
      args.columns = value.split(';').filter(Boolean).map(p => p.split(',').map(Number))
    } else throw new Error(`unknown argument ${key}`)
  }
  if (!Number.isInteger(args.port)) throw new Error('usage: node probe.js PORT [options]')
  return args
}

function finish (bot, code, report) {
  process.stdout.write(JSON.stringify(report) + '\n')
  try { bot.quit() } catch (_) {}
  // Give the quit packet a moment to leave, without waiting on the server.
  setTimeout(() => process.exit(code), 200).unref()
}

function main () {
  const args = parseArgs(process.argv.slice(2))
  const started = Date.now()
  const bot = mineflayer.createBot({
    host: '127.0.0.1',
    port: args.port,
    username: args.name,
    version: '1.20.1',
    auth: 'offline',
    viewDistance: args.view,
    hideErrors: true
  })
  const report = { ok: false, name: args.name }
  const chunks = new Set()
  let done = false
  const fail = (error) => {
    if (done) return
    done = true
    report.error = String(error)
    report.chunks = chunks.size
    finish(bot, 1, report)
  }
  setTimeout(() => fail(`timed out after ${args.timeout} s`), args.timeout * 1000).unref()
  bot.on('kicked', reason => fail(`kicked: ${JSON.stringify(reason)}`))
  bot.on('error', error => fail(`error: ${error && error.message ? error.message : error}`))
  bot.on('end', reason => fail(`connection ended: ${reason}`))

  bot._client.on('map_chunk', packet => {
    chunks.add(`${packet.x},${packet.z}`)
    if (args.expectChunks > 0 && chunks.size === args.expectChunks && report.all_chunks_ms === undefined) {
      report.all_chunks_ms = Date.now() - started
    }
  })

  bot.once('spawn', () => {
    report.spawn_ms = Date.now() - started
    report.spawn = vec(bot.entity.position)
    report.game_mode = bot.game.gameMode
    report.min_y = bot.game.minY
    report.height = bot.game.height
    report.health = bot.health
  })

  // Each physics tick (20 Hz): check whether everything asked for is there yet.
  const check = () => {
    if (done || report.spawn === undefined) return
    const below = bot.blockAt(bot.entity.position.offset(0, -0.5, 0))
    if (!below || !bot.entity.onGround) return
    if (args.expectChunks > 0 && chunks.size < args.expectChunks) return
    const columns = []
    for (const [x, z] of args.columns) {
      const column = topOf(bot, x, z)
      if (column === null) return // not loaded yet
      columns.push(column)
    }
    done = true
    Object.assign(report, {
      ok: true,
      position: vec(bot.entity.position),
      on_ground: bot.entity.onGround,
      below: below.name,
      below_y: below.position.y,
      chunks: chunks.size,
      columns
    })
    finish(bot, 0, report)
  }
  bot.on('physicsTick', check)
}

// The highest non-air block of column (x, z), its biome, or null when not loaded.
function topOf (bot, x, z) {
  const minY = bot.game.minY
  for (let y = minY + bot.game.height - 1; y >= minY; y--) {
    const block = bot.blockAt(new Vec3(x, y, z))
    if (block === null) return null
    if (block.name !== 'air' && block.name !== 'cave_air' && block.name !== 'void_air') {
      const biome = bot.registry.biomes[block.biome.id]
      return { x, z, y, block: block.name, biome: biome ? biome.name : `#${block.biome.id}` }
    }
  }
  return { x, z, y: minY - 1, block: 'air', biome: '' }
}

function vec (v) {
  return { x: v.x, y: v.y, z: v.z }
}

main()
