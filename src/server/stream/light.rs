//! Light across chunk borders in the server: a chunk is sent with its own light as soon as it
//! is built; once its eight neighbours are loaded too, its light is joined with theirs
//! ([`Light::joined`]) and, where that lets light in, sent again. Joining reads only the
//! chunks' own light, so the light a client ends up with does not depend on the order the
//! chunks were built or loaded in.

use std::sync::Arc;

use valence::prelude::ChunkPos;
use valence::protocol::{CompressionThreshold, PacketEncoder};

use crate::chunkgen::Light;

/// A chunk's light: its own (what its neighbours' joining reads) and what clients are sent.
#[derive(Clone)]
pub struct Lit {
    /// Its light alone.
    pub own: Arc<Light>,
    /// The encoded light packet of `own`.
    own_packet: Arc<[u8]>,
    joined: Joined,
}

/// Whether a chunk's light has been joined with its neighbours'.
#[derive(Clone)]
enum Joined {
    /// Not yet (some neighbour was not loaded): clients have its own light.
    No,
    /// Yes, and its own light was already right.
    Same,
    /// Yes, and light came in across its borders: this packet.
    Brighter(Arc<[u8]>),
}

impl Lit {
    /// A chunk's own light, not yet joined.
    pub fn alone(pos: ChunkPos, own: Light, compression: CompressionThreshold) -> anyhow::Result<Lit> {
        let own_packet = encode(pos, &own, compression)?;
        Ok(Lit { own: Arc::new(own), own_packet, joined: Joined::No })
    }

    /// The light packet clients get.
    pub fn packet(&self) -> &Arc<[u8]> {
        match &self.joined {
            Joined::Brighter(packet) => packet,
            Joined::No | Joined::Same => &self.own_packet,
        }
    }

    /// Whether its light has been joined with its neighbours'.
    pub fn is_joined(&self) -> bool {
        !matches!(self.joined, Joined::No)
    }

    /// Its light will be joined again (a neighbour changed).
    pub fn unjoin(&mut self) {
        self.joined = Joined::No;
    }

    /// Records the result of [`Light::joined`] for the chunk at `pos`.
    pub fn set_joined(
        &mut self,
        pos: ChunkPos,
        joined: Option<&Light>,
        compression: CompressionThreshold,
    ) -> anyhow::Result<()> {
        self.joined = match joined {
            None => Joined::Same,
            Some(light) => Joined::Brighter(encode(pos, light, compression)?),
        };
        Ok(())
    }
}

/// The chunk at `pos` and its eight neighbours, rows north to south, each west to east (the
/// order [`Light::joined`] takes them in).
pub fn area(pos: ChunkPos) -> [ChunkPos; 9] {
    std::array::from_fn(|i| ChunkPos::new(pos.x + i as i32 % 3 - 1, pos.z + i as i32 / 3 - 1))
}

/// `light` for the chunk at `pos` as a ready-to-send packet, encoded the way valence encodes
/// everything else.
fn encode(pos: ChunkPos, light: &Light, compression: CompressionThreshold) -> anyhow::Result<Arc<[u8]>> {
    let mut encoder = PacketEncoder::new();
    encoder.set_compression(compression);
    encoder.append_packet(&light.packet(pos))?;
    Ok(Arc::from(&encoder.take()[..]))
}
