//! `pack --resume`: finds the partial run of the same output to continue, and starts the new
//! trajectory with what that run recorded up to its last checkpoint.
//!
//! The candidates are `<output>.part` (a killed run), `<output>` (a run that was interrupted or
//! reached its --max-time) and `<output>.resume` (a resume that was itself killed while it
//! copied). Of those made by the same configuration and pellet, the one with the latest
//! checkpoint wins. Each is read past a damaged chunk (its checkpoint lost, the ones before and
//! after it kept); a candidate that does not read at all, or none of whose checkpoints reads, is
//! refused and left alone, since the resumed run would write over it.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};

use pellet_io::{IoError, ReadOptions, Trajectory, TrajectoryWriter};
use pellet_pack::{resume_conflicts, Checkpoint, Ending, PackConfig, PackOptions};

/// A run to continue.
pub struct Source {
    path: PathBuf,
    trajectory: Trajectory,
    checkpoint_bytes: Vec<u8>,
    /// Its last checkpoint.
    pub checkpoint: Checkpoint,
}

fn with_suffix(output: &str, suffix: &str) -> PathBuf {
    PathBuf::from(format!("{output}{suffix}"))
}

/// The run to continue, if any. A candidate made by another configuration or pellet is an
/// error when no compatible one exists (continuing would mix two runs; starting over would
/// overwrite it), and so is one that does not read: resuming would write over it.
pub fn find(output: &str, config: &PackConfig, pellet_bytes: &[u8]) -> anyhow::Result<Option<Source>> {
    let scan = scan(output, config, pellet_bytes)?;
    if let Some((shown, why)) = &scan.unreadable {
        bail!("cannot resume: {shown}: {why}; it was left as it is: remove or rename it, or give another -o, to start over");
    }
    let found = scan.latest()?;
    if let Some(source) = &found {
        if let Some(Ending::TimeLimit) = source.checkpoint.run.ending {
            let t = source.checkpoint.time_s();
            if config.max_time_s <= t {
                let shown = source.path.display();
                bail!("{shown}: the run reached its --max-time at t = {t:.3} s; give a larger --max-time to go on");
            }
        }
        for damage in &source.trajectory.damaged {
            eprintln!(
                "pack: warning: {}: {damage}; resuming from its last checkpoint that reads",
                source.path.display()
            );
        }
    }
    Ok(found)
}

/// The compatible candidate with the latest checkpoint, unless the run settled; unlike
/// [`find`], a run that reached this configuration's --max-time is returned too (`--park`).
pub fn latest(output: &str, config: &PackConfig, pellet_bytes: &[u8]) -> anyhow::Result<Option<Source>> {
    scan(output, config, pellet_bytes)?.latest()
}

/// What the candidates hold.
struct Scan {
    best: Option<Source>,
    /// Why the first candidate made by another run was passed over.
    refused: Option<String>,
    /// The first candidate that does not read, and why.
    unreadable: Option<(String, String)>,
}

fn scan(output: &str, config: &PackConfig, pellet_bytes: &[u8]) -> anyhow::Result<Scan> {
    let mut found = Scan { best: None, refused: None, unreadable: None };
    for path in [with_suffix(output, ".part"), PathBuf::from(output), with_suffix(output, ".resume")] {
        if !path.is_file() {
            continue;
        }
        let shown = path.display().to_string();
        let mut trajectory = match read_run(&path, ReadOptions::default()) {
            Ok(Some(t)) => t,
            Ok(None) => continue,
            Err(why) => {
                found.unreadable.get_or_insert((shown, why));
                continue;
            }
        };
        let Some(checkpoint_bytes) = trajectory.checkpoint.take() else {
            // A run killed before its first checkpoint holds nothing to go on from; a damaged
            // one may have lost its checkpoints.
            if let Some(damage) = trajectory.damaged.first() {
                found.unreadable.get_or_insert((shown, format!("no checkpoint reads ({damage})")));
            }
            continue;
        };
        if let (Some(damage), None) = (trajectory.damaged.first(), trajectory.run.get("config")) {
            found.unreadable.get_or_insert((shown, format!("its run metadata does not read ({damage})")));
            continue;
        }
        if trajectory.pellet_files.first().map(Vec::as_slice) != Some(pellet_bytes) {
            found.refused.get_or_insert(format!("{shown} was made with another pellet file"));
            continue;
        }
        let recorded = trajectory.run.get("config").map(String::as_str).unwrap_or("");
        let conflicts = resume_conflicts(recorded, config);
        if !conflicts.is_empty() {
            found.refused.get_or_insert(format!("{shown} was made with other settings ({})", conflicts.join(", ")));
            continue;
        }
        let checkpoint = Checkpoint::decode(&checkpoint_bytes, &shown)?;
        if found.best.as_ref().is_none_or(|b| checkpoint.time_s() > b.checkpoint.time_s()) {
            found.best = Some(Source { path, trajectory, checkpoint_bytes, checkpoint });
        }
    }
    Ok(found)
}

impl Scan {
    fn latest(self) -> anyhow::Result<Option<Source>> {
        match (self.best, self.refused) {
            (Some(source), _) => {
                let (t, shown) = (source.checkpoint.time_s(), source.path.display());
                match source.checkpoint.run.ending {
                    Some(Ending::Settled) => bail!("{shown}: the run settled at t = {t:.3} s; nothing to resume"),
                    _ => Ok(Some(source)),
                }
            }
            (None, Some(why)) => bail!("cannot resume: {why}; delete it, or run without --resume to start over"),
            (None, None) => Ok(None),
        }
    }
}

/// Reads a trajectory of a run, past damaged chunks: `None` for a run killed as it began,
/// which recorded nothing. The error is the reason alone, without a remedy meant for other
/// tools.
fn read_run(path: &Path, options: ReadOptions) -> Result<Option<Trajectory>, String> {
    let shown = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    let options = ReadOptions { skip_damage: true, ..options };
    match pellet_io::read_trajectory_with(&bytes, &shown, options) {
        Ok(t) => Ok(Some(t)),
        Err(IoError::CutInHeader { .. }) => Ok(None),
        Err(IoError::Corrupt { reason, .. }) => Err(reason.split("; ").next().unwrap_or_default().to_string()),
        Err(e) => Err(e.to_string()),
    }
}

/// `options` with the settings whose default has changed over packbed's versions (the
/// stepper, the contact patch, the velocity stepper's step) taken from the run being continued
/// where the user left them out: a run keeps the stepper it was made with when the same command
/// resumes it. The first candidate whose run metadata reads decides; with none, `options` are
/// returned as they are.
pub fn follow_recorded(mut options: PackOptions, output: &str) -> PackOptions {
    let given = [options.contact_patch, options.step_travel, options.max_step];
    if options.stepper.is_some() && given.iter().all(Option::is_some) {
        return options;
    }
    let recorded = [with_suffix(output, ".part"), PathBuf::from(output), with_suffix(output, ".resume")]
        .into_iter()
        .filter(|path| path.is_file())
        .filter_map(|path| read_run(&path, ReadOptions { skip_frames: true, ..ReadOptions::default() }).ok()?)
        .find_map(|t| serde_json::from_str::<PackConfig>(t.run.get("config")?).ok());
    if let Some(recorded) = recorded {
        options.stepper.get_or_insert(recorded.stepper);
        options.contact_patch.get_or_insert(recorded.contact_patch_dp);
        options.step_travel.get_or_insert(recorded.step_travel_dp);
        options.max_step.get_or_insert(recorded.max_step_s);
    }
    options
}

/// The run at `output` in a few words ("a run interrupted at t = 1.185 s"), if it stopped
/// before its end: interrupted, or a parked copy of a killed run. It is then the only copy of
/// that run, which `--resume` continues. A settled run, or one that reached its --max-time, is
/// finished; a file that is no run read here is not one.
pub fn unfinished(output: &str) -> Option<String> {
    let path = Path::new(output);
    if !path.is_file() {
        return None;
    }
    let t = read_run(path, ReadOptions { skip_frames: true, ..ReadOptions::default() }).ok()??;
    let checkpoint = Checkpoint::decode(t.checkpoint.as_deref()?, output).ok()?;
    let t = checkpoint.time_s();
    match checkpoint.run.ending {
        Some(Ending::Settled | Ending::TimeLimit) => None,
        Some(Ending::Interrupted) => Some(format!("a run interrupted at t = {t:.3} s")),
        None => Some(format!("a partial run (its last checkpoint at t = {t:.3} s)")),
    }
}

impl Source {
    /// The builds that made this run, continued by `current`: the source's recorded `build`
    /// (`unrecorded` for runs from before it was recorded), then `; from t = <checkpoint> s
    /// <current>` unless `current` made its last leg too.
    pub fn build_history(&self, current: &str) -> String {
        build_history(self.trajectory.run.get("build").map(String::as_str), self.checkpoint.time_s(), current)
    }

    /// Writes to `path` a trajectory that holds only what `--resume` needs of this run: its run
    /// metadata (configuration and build history as recorded), pellet files and tube, every
    /// energy record up to the checkpoint, the last frame before it and the checkpoint itself.
    /// Copied to `<output>` on any machine, `pack --resume` continues the run from there; the
    /// frames before the checkpoint (all but that last one) are not kept. The source is left
    /// alone. Returns the checkpoint's time (s).
    pub fn park(&self, path: &Path) -> anyhow::Result<f64> {
        let t = self.checkpoint.time_s();
        let shown = self.path.display();
        let tube = self.trajectory.tube.as_ref().with_context(|| format!("{shown}: no tube attachment"))?;
        let run = &self.trajectory.run;
        let mut writer = TrajectoryWriter::create_with_run(path, run, &self.trajectory.pellet_files, tube)?;
        if let Some(frame) = self.trajectory.frames.iter().rev().find(|f| f.time_s < t) {
            writer.write_frame(frame)?;
        }
        for record in self.trajectory.energy.iter().filter(|e| e.time_s <= t) {
            writer.write_energy(record)?;
        }
        writer.write_checkpoint(t, &self.checkpoint_bytes)?;
        writer.finish()?;
        Ok(t)
    }

    /// Moves the source to `<output>.resume`, out of the way of the new `<output>.part` (which
    /// may be the source itself) and of the final name. Call before creating the new writer.
    pub fn set_aside(mut self, output: &str) -> anyhow::Result<Self> {
        let aside = with_suffix(output, ".resume");
        if self.path != aside {
            std::fs::rename(&self.path, &aside)
                .with_context(|| format!("cannot move {} to {}", self.path.display(), aside.display()))?;
            self.path = aside;
        }
        Ok(self)
    }

    /// Writes into `writer` the source's frames before the checkpoint, its energy records up
    /// to it and the checkpoint itself, then deletes the source (set aside first): the new
    /// trajectory alone can be resumed from here on.
    pub fn copy_into(self, writer: &mut TrajectoryWriter) -> anyhow::Result<Checkpoint> {
        let t = self.checkpoint.time_s();
        // A frame at the checkpoint's time is written after it (by the resumed run); the step
        // that ended there wrote its energy record before it.
        for frame in self.trajectory.frames.iter().filter(|f| f.time_s < t) {
            writer.write_frame(frame)?;
        }
        for record in self.trajectory.energy.iter().filter(|e| e.time_s <= t) {
            writer.write_energy(record)?;
        }
        writer.write_checkpoint(t, &self.checkpoint_bytes)?;
        remove_if_present(&self.path)?;
        Ok(self.checkpoint)
    }
}

/// See [`Source::build_history`].
fn build_history(recorded: Option<&str>, resumed_at_s: f64, current: &str) -> String {
    let recorded = recorded.unwrap_or("unrecorded");
    // `current` made the last leg: the whole history, or its part after the last "… s ".
    if recorded == current || recorded.ends_with(&format!(" s {current}")) {
        recorded.to_string()
    } else {
        format!("{recorded}; from t = {resumed_at_s:.3} s {current}")
    }
}

fn remove_if_present(path: &Path) -> anyhow::Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("cannot remove {}", path.display()))
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::build_history;

    #[test]
    fn each_leg_of_a_resumed_run_names_its_build() {
        assert_eq!(build_history(Some("git a"), 2.0, "git a"), "git a");
        assert_eq!(build_history(Some("git a"), 2.0, "git b"), "git a; from t = 2.000 s git b");
        let two = "git a; from t = 2.000 s git b";
        assert_eq!(build_history(Some(two), 3.5, "git b"), two);
        assert_eq!(build_history(Some(two), 3.5, "git a"), format!("{two}; from t = 3.500 s git a"));
        assert_eq!(build_history(None, 24.23, "git c"), "unrecorded; from t = 24.230 s git c");
    }
}
