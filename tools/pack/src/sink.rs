//! Where a run's frames, energy records and checkpoints go: the MCAP trajectory, with progress
//! on stderr.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use pellet_io::{EnergyRecord, Frame, TrajectoryWriter};
use pellet_pack::{Progress, RunSink};

/// Writes frames and energy records to the MCAP file and shows progress.
pub struct McapSink {
    pub writer: TrajectoryWriter,
    stop: Arc<AtomicBool>,
    pub bar: Option<indicatif::ProgressBar>,
    quiet: bool,
    last_line: Instant,
    last_flush: f64,
}

impl McapSink {
    pub fn new(writer: TrajectoryWriter, stop: Arc<AtomicBool>, quiet: bool) -> Self {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = indicatif::ProgressBar::new_spinner();
            bar.enable_steady_tick(Duration::from_millis(200));
            bar
        });
        McapSink { writer, stop, bar, quiet, last_line: Instant::now(), last_flush: 0.0 }
    }
}

impl RunSink for McapSink {
    fn frame(&mut self, frame: &Frame) -> Result<(), String> {
        self.writer.write_frame(frame).map_err(|e| e.to_string())?;
        // Close the chunk once per simulated second: a killed run loses at most that.
        if frame.time_s - self.last_flush >= 1.0 {
            self.last_flush = frame.time_s;
            self.writer.flush().map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    fn energy(&mut self, record: &EnergyRecord) -> Result<(), String> {
        self.writer.write_energy(record).map_err(|e| e.to_string())
    }

    fn progress(&mut self, p: &Progress) {
        if self.quiet {
            return;
        }
        let of = p.target.map(|n| format!("/{n}")).unwrap_or_default();
        let msg = format!(
            "t = {:.2} s  pellets {}{of}  bed top {:.1} mm  kinetic energy {:.3e} J",
            p.time_s,
            p.pellets,
            p.bed_top_m * 1e3,
            p.kinetic_j
        );
        match &self.bar {
            Some(bar) => bar.set_message(msg),
            None => {
                // Not a terminal (make, CI): a plain line every few seconds.
                if self.last_line.elapsed() >= Duration::from_secs(5) {
                    self.last_line = Instant::now();
                    eprintln!("pack: {msg}");
                }
            }
        }
    }

    fn should_stop(&self) -> bool {
        self.stop.load(Ordering::SeqCst)
    }

    fn checkpoint(&mut self, time_s: f64, bytes: &[u8]) -> Result<(), String> {
        self.writer.write_checkpoint(time_s, bytes).map_err(|e| e.to_string())
    }
}
