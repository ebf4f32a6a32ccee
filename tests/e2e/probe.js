'use strict'
// Joins an infiniterra server as a headless Minecraft 1.20.1 player (mineflayer) and prints
// what it saw as one JSON line on stdout. Driven by tests/server_e2e.rs.
//
// usage: node probe.js PORT [--name NAME] [--view CHUNKS] [--expect-chunks N]
//                           [--columns "x,z;x,z;..."] [--timeout SECONDS]
//
// Exit code 0 with {"ok":true,...}; 1 with {"ok":false,"error":...} on a kick, an error or
// the timeout. Every wait is for an event or a condition, bounded by the timeout.

const { createBot } = require('./bot')
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
  const bot = createBot(args.port, args.name, args.view)
  const report = { ok: false, name: args.name }
  const chunks = new Set()
  const lit = new Map() // chunk → its latest light packet (the server sends it after the chunk)
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

  bot._client.on('update_light', packet => lit.set(`${packet.chunkX},${packet.chunkZ}`, packet))

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
      if (!lit.has(`${Math.floor(x / 16)},${Math.floor(z / 16)}`)) return
      const column = topOf(bot, x, z, lit)
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
      lit_chunks: lit.size,
      columns
    })
    finish(bot, 0, report)
  }
  bot.on('physicsTick', check)
}

// Blocks the generator places on the ground as vegetation (see src/chunkgen/plants.rs), and
// the layer of snow the snow pass lays over snowy biomes (src/chunkgen/passes/snow.rs).
const PLANTS = new Set([
  'grass', 'tall_grass', 'fern', 'large_fern', 'dead_bush', 'cactus', 'sunflower', 'lilac', 'rose_bush', 'peony',
  'dandelion', 'poppy', 'blue_orchid', 'allium', 'azure_bluet', 'red_tulip', 'orange_tulip', 'white_tulip',
  'pink_tulip', 'oxeye_daisy', 'cornflower', 'lily_of_the_valley', 'pink_petals', 'sweet_berry_bush',
  'brown_mushroom', 'red_mushroom', 'bamboo', 'azalea', 'flowering_azalea', 'sugar_cane', 'lily_pad', 'snow'
])

// Blocks of trees besides logs and leaves, huge mushrooms' among them (src/chunkgen/trees.rs).
const TREE_PARTS = new Set(['mangrove_roots', 'vine', 'cocoa', 'mushroom_stem', 'red_mushroom_block', 'brown_mushroom_block'])

// The ground of column (x, z): its highest block that is neither air, a plant nor part of a tree, with
// its biome and sky light, and whether anything (a tree) stands above it; null when the
// column is not loaded yet.
function topOf (bot, x, z, lit) {
  const minY = bot.game.minY
  let covered = false
  for (let y = minY + bot.game.height - 1; y >= minY; y--) {
    const block = bot.blockAt(new Vec3(x, y, z))
    if (block === null) return null
    if (block.name === 'air' || block.name === 'cave_air' || block.name === 'void_air') continue
    if (PLANTS.has(block.name)) continue // vegetation stands on the ground, it is not the ground
    if (block.name.endsWith('_log') || block.name.endsWith('_leaves') || TREE_PARTS.has(block.name)) {
      covered = true
      continue
    }
    const biome = bot.registry.biomes[block.biome.id]
    return {
      x,
      z,
      y,
      block: block.name,
      biome: biome ? biome.name : `#${block.biome.id}`,
      covered,
      sky_light_above: skyLight(bot, lit, x, y + 1, z),
      sky_light_at: skyLight(bot, lit, x, y, z),
      sky_light_below: skyLight(bot, lit, x, y - 1, z)
    }
  }
  return { x, z, y: minY - 1, block: 'air', biome: '', covered }
}

// Sky light at a block as the vanilla client reads the last light packet of its chunk: one
// 2048-byte array per section whose mask bit is set (bit 0 = the section below the world),
// value i in byte i >> 1, low nibble first. (prismarine-chunk decodes these arrays as
// big-endian longs, which mirrors x inside every 16 values, so it is not used here.)
function skyLight (bot, lit, x, y, z) {
  const packet = lit.get(`${Math.floor(x / 16)},${Math.floor(z / 16)}`)
  const section = ((y - bot.game.minY) >> 4) + 1
  const bit = (mask, i) => {
    const long = mask[Math.floor(i / 64)]
    if (!long) return 0
    const [hi, lo] = long
    return i % 64 < 32 ? (lo >>> (i % 64)) & 1 : (hi >>> (i % 64 - 32)) & 1
  }
  if (!bit(packet.skyLightMask, section)) return bit(packet.emptySkyLightMask, section) ? 0 : null
  let array = 0
  for (let i = 0; i < section; i++) array += bit(packet.skyLightMask, i)
  const index = (((y - bot.game.minY) & 15) << 8) | ((z & 15) << 4) | (x & 15)
  return (packet.skyLight[array][index >> 1] >> ((index & 1) * 4)) & 15
}

function vec (v) {
  return { x: v.x, y: v.y, z: v.z }
}

main()
