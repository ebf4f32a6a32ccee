// The one way the end-to-end scripts join the server: an offline 1.20.1 client on loopback.
const mineflayer = require('mineflayer')

function createBot (port, username, viewDistance) {
  return mineflayer.createBot({
    host: '127.0.0.1',
    port,
    username,
    version: '1.20.1',
    auth: 'offline',
    viewDistance,
    hideErrors: true
  })
}

module.exports = { createBot }
