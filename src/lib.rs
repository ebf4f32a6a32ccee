//! infiniterra: a Minecraft world-generator server whose terrain is learned, infinite and
//! seed-consistent.
//!
//! This crate is the owner-facing edge: configuration, the command line, maps and exports,
//! benchmarks and (later) the Minecraft server. The terrain itself lives in the
//! `infiniterra-terrain` crate, which knows nothing of Minecraft.

pub mod biome;
pub mod chunkgen;
pub mod cli;
pub mod config;
pub mod draw;
pub mod export;
pub mod lab;
pub mod npy;
pub mod pregen;
pub mod render;
pub mod server;
pub mod world;

pub use infiniterra_terrain as terrain;
