//! Start-up announcement and shutdown: "listening on …" once the port really accepts
//! connections, and a clean stop on `stop`, Ctrl-C or SIGTERM.

use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use valence::app::AppExit;
use valence::prelude::*;
use valence::protocol::packets::play::DisconnectS2c;
use valence::protocol::WritePacket;

use super::ServeError;

/// How long the network plugin may take to open the port before start-up counts as failed.
const LISTEN_TIMEOUT: Duration = Duration::from_secs(20);
/// Exit code: 0 success, 1 runtime failure.
const FAILED: u8 = 1;

/// Set from any thread (console, signal handler) to ask the server to stop.
#[derive(Resource, Clone, Default)]
pub struct StopRequest(Arc<AtomicBool>);

impl StopRequest {
    /// Asks for a stop.
    pub fn request(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    fn requested(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

/// How the app ended, read after `App::run` returns.
#[derive(Resource, Clone, Default)]
pub struct ExitCode(Arc<AtomicU8>);

impl ExitCode {
    fn fail(&self) {
        self.0.store(FAILED, Ordering::SeqCst);
    }

    /// `Ok` unless something set a failure.
    pub fn result(&self) -> Result<(), ServeError> {
        match self.0.load(Ordering::SeqCst) {
            0 => Ok(()),
            _ => Err(ServeError::Runtime(anyhow::anyhow!("the server stopped after an error (see the log above)"))),
        }
    }
}

#[derive(Resource)]
struct Listening {
    address: SocketAddr,
    since: Instant,
    announced: bool,
}

/// Tick at which players were told the server is closing.
#[derive(Resource, Default)]
struct Stopping(Option<i64>);

/// Installs the signal handler and the start/stop systems.
pub fn build(app: &mut App, address: SocketAddr) -> anyhow::Result<()> {
    let stop = StopRequest::default();
    let flag = stop.clone();
    ctrlc::set_handler(move || {
        if flag.requested() {
            // A second Ctrl-C: the owner does not want to wait.
            std::process::exit(130);
        }
        flag.request();
    })?;
    app.insert_resource(stop)
        .insert_resource(Stopping::default())
        .insert_resource(Listening { address, since: Instant::now(), announced: false })
        .add_systems(Update, (announce_listening, stop_when_asked));
    Ok(())
}

/// valence opens the port on its own runtime and only logs a failure: probe it until it
/// accepts, then print the line owners (and tests) wait for.
fn announce_listening(mut listening: ResMut<Listening>, exit_code: Res<ExitCode>, mut exit: EventWriter<AppExit>) {
    if listening.announced {
        return;
    }
    let probe = SocketAddr::new(reachable(listening.address.ip()), listening.address.port());
    if TcpStream::connect_timeout(&probe, Duration::from_millis(200)).is_ok() {
        listening.announced = true;
        say!("listening on {} (Minecraft Java Edition 1.20.1); type `help` for console commands", listening.address);
    } else if listening.since.elapsed() > LISTEN_TIMEOUT {
        tracing::error!("the server did not start listening on {} (see the log above)", listening.address);
        exit_code.fail();
        exit.send(AppExit);
    }
}

/// The unspecified address cannot be connected to; the loopback of its family can.
fn reachable(ip: IpAddr) -> IpAddr {
    match ip {
        IpAddr::V4(v4) if v4.is_unspecified() => IpAddr::V4(Ipv4Addr::LOCALHOST),
        IpAddr::V6(v6) if v6.is_unspecified() => IpAddr::V6(Ipv6Addr::LOCALHOST),
        other => other,
    }
}

/// First tick after a stop request: disconnect everyone with a reason. Next tick (once those
/// packets have left): exit the app.
fn stop_when_asked(
    stop: Res<StopRequest>,
    mut stopping: ResMut<Stopping>,
    server: Res<Server>,
    mut clients: Query<&mut Client>,
    mut exit: EventWriter<AppExit>,
) {
    if !stop.requested() {
        return;
    }
    match stopping.0 {
        None => {
            say!("stopping…");
            for mut client in &mut clients {
                client.write_packet(&DisconnectS2c { reason: "The server is stopping.".into_cow_text() });
            }
            stopping.0 = Some(server.current_tick());
        }
        Some(tick) if server.current_tick() > tick => {
            say!("stopped");
            exit.send(AppExit);
        }
        Some(_) => {}
    }
}
