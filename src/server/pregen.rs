//! The console's `pregen` commands (Chunky's conventions: start, pause, continue, cancel
//! with confirmation, progress), and resuming a task when the server starts again.
//!
//! The work itself is done by the chunk workers between players' chunks (see
//! `stream::workers`); this module only starts, steers and reports the task.

use std::path::Path;
use std::sync::{Arc, Mutex, PoisonError};

use valence::prelude::*;

use super::dimension::WorldSetup;
use super::stream::Streamer;
use crate::pregen::{progress, thousands, Hooks, Job, Plan, Progress, Shape, Shard, State, Task};

/// Console help for the pregen commands.
pub const HELP: &str = "  pregen start <x> <z> <radius> [square|circle]   pre-generate around block x, z
  pregen pause | continue | progress              steer or show the running task
  pregen cancel                                   stop the task (asks for `pregen confirm`)";

/// The task the server is working on, shared with `serve` so it can be stopped cleanly.
#[derive(Resource, Clone, Default)]
pub struct PregenControl {
    job: Arc<Mutex<Option<Arc<Job>>>>,
    confirm_cancel: bool,
}

impl PregenControl {
    /// The task, if one is active.
    pub fn job(&self) -> Option<Arc<Job>> {
        self.job.lock().unwrap_or_else(PoisonError::into_inner).clone()
    }

    /// Any command other than `pregen confirm` keeps the task (Chunky's convention).
    pub fn forget_confirmation(&mut self) {
        self.confirm_cancel = false;
    }

    fn set(&self, job: Option<Arc<Job>>) {
        *self.job.lock().unwrap_or_else(PoisonError::into_inner) = job;
    }
}

/// Adds the resource and the start-up check for an unfinished task.
pub fn build(app: &mut App, control: PregenControl) {
    app.insert_resource(control).add_systems(Update, resume_on_start);
}

/// A task that was running when the server stopped (or crashed) resumes; a paused one waits
/// for `pregen continue`. Runs once, on the first tick the workers exist.
fn resume_on_start(
    setup: Res<WorldSetup>,
    control: Res<PregenControl>,
    streamer: Option<Res<Streamer>>,
    mut checked: Local<bool>,
) {
    let Some(streamer) = streamer else { return };
    if std::mem::replace(&mut *checked, true) || setup.store.is_none() {
        return;
    }
    let path = progress::path(&setup.config.world.directory, Shard::ALL);
    match Progress::load(&path) {
        Ok(Some(p)) if p.state == State::Running => {
            say!("pregen: resuming {} after chunk {} of {}", p.task, thousands(p.done), thousands(p.total));
            start(&setup, &control, &streamer, p.task, p.done);
        }
        Ok(Some(p)) if p.state == State::Paused => say!(
            "pregen: {} is paused at {}/{} chunks{}; `pregen continue` resumes it",
            p.task,
            thousands(p.done),
            thousands(p.total),
            p.error.map(|e| format!(" ({e})")).unwrap_or_default()
        ),
        Ok(_) => {}
        Err(e) => say!("pregen: {e:#}"),
    }
}

/// Runs one `pregen …` console command (`args` are the words after `pregen`).
pub fn command(args: &[&str], setup: &WorldSetup, control: &mut PregenControl, streamer: Option<&Streamer>) {
    let confirming = std::mem::take(&mut control.confirm_cancel);
    let Some(streamer) = streamer else {
        say!("pregen: the chunk workers are not running");
        return;
    };
    if setup.store.is_none() {
        say!("pregen: saving is off (world.save_chunks = false), so there is nothing to pre-generate into");
        return;
    }
    let active = control.job().filter(|j| {
        let s = j.status();
        !s.cancelled && s.state != State::Finished
    });
    match args {
        ["start", rest @ ..] => {
            if let Some(job) = &active {
                say!("pregen: a task is already active ({}); `pregen cancel` it first", job.status().line());
                return;
            }
            match parse_task(rest) {
                Ok(task) => start(setup, control, streamer, task, 0),
                Err(e) => say!("pregen start: {e}\n{HELP}"),
            }
        }
        ["pause"] => match &active {
            Some(job) if job.pause() => say!("pregen: paused; `pregen continue` resumes"),
            Some(_) => say!("pregen: the task is not running"),
            None => say!("pregen: no task"),
        },
        ["continue"] => match &active {
            Some(job) if job.resume() => say!("pregen: continuing"),
            Some(_) => say!("pregen: the task is already running"),
            None => continue_saved(setup, control, streamer),
        },
        ["cancel"] => match &active {
            Some(job) => {
                control.confirm_cancel = true;
                say!(
                    "pregen: cancel {} at {}? Type `pregen confirm` to cancel it; any other command keeps it",
                    job.plan().task(),
                    job.status().line().trim_start_matches("pregen: ")
                );
            }
            None => say!("pregen: no task"),
        },
        ["confirm"] => match (&active, confirming) {
            (Some(job), true) => {
                job.cancel();
                streamer.set_pregen(None);
                control.set(None);
            }
            _ => say!("pregen: nothing to confirm (`pregen cancel` first)"),
        },
        ["progress"] | [] => match control.job() {
            Some(job) => say!("{}", job.status().line()),
            None => say!("pregen: no task"),
        },
        _ => say!("pregen: unknown subcommand\n{HELP}"),
    }
}

fn parse_task(args: &[&str]) -> Result<Task, String> {
    let number = |name: &str, s: &str| s.parse::<i64>().map_err(|_| format!("{name} {s:?} is not a whole number"));
    let task = match args {
        [x, z, r] | [x, z, r, _] => Task {
            center_x: number("x", x)?,
            center_z: number("z", z)?,
            radius: number("radius", r)?,
            shape: args.get(3).map_or(Ok(Shape::Square), |s| s.parse())?,
        },
        _ => return Err("expected <x> <z> <radius> [square|circle]".into()),
    };
    task.validate()?;
    Ok(task)
}

fn continue_saved(setup: &WorldSetup, control: &PregenControl, streamer: &Streamer) {
    let path = progress::path(&setup.config.world.directory, Shard::ALL);
    match Progress::load(&path) {
        Ok(Some(p)) if p.state != State::Finished => start(setup, control, streamer, p.task, p.done),
        Ok(_) => say!("pregen: no task to continue"),
        Err(e) => say!("pregen: {e:#}"),
    }
}

fn start(setup: &WorldSetup, control: &PregenControl, streamer: &Streamer, task: Task, done: u64) {
    let Some(store) = setup.store.clone() else { return };
    let dir: &Path = &setup.config.world.directory;
    let plan = Plan::new(task, Shard::ALL);
    let (total, regions) = (plan.total(), plan.regions().len());
    let waker = streamer.waker();
    let job = Job::start(
        plan,
        setup.config.world.seed,
        store,
        progress::path(dir, Shard::ALL),
        done,
        Hooks {
            report_every: crate::pregen::REPORT_EVERY,
            report: Box::new(|line| say!("{line}")),
            on_work: Box::new(move || waker.wake()),
        },
    );
    match job {
        Ok(job) => {
            say!("pregen: {task}: {} chunks in {regions} region files", thousands(total));
            streamer.set_pregen(Some(job.clone()));
            control.set(Some(job));
        }
        Err(e) => say!("pregen: cannot write the progress file in {}: {e}", dir.display()),
    }
}
