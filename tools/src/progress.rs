//! The commands' one progress bar: hidden until the work has lasted a second, so quick work
//! prints nothing, and cleared when it ends. [`with_bar`] shows the engine's long work
//! (`kage::progress::Progress`) on one.
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::borrow::Cow;
use std::time::Instant;

/// A bar counting `unit`s, with a message before it; cleared when dropped.
pub struct Bar {
    bar: ProgressBar,
    start: Instant,
}

impl Bar {
    pub fn new(len: u64, unit: &str) -> Bar {
        let template =
            format!("{{msg}} [{{bar:30}}] {{pos}}/{{len}} {unit}, {{elapsed}} elapsed, {{eta}} left");
        let style = ProgressStyle::with_template(&template).expect("static template");
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden()).with_style(style);
        Bar { bar, start: Instant::now() }
    }

    pub fn message(&self, message: impl Into<Cow<'static, str>>) {
        self.bar.set_message(message);
    }

    /// Counts `steps` more done.
    pub fn advance(&self, steps: u64) {
        self.bar.inc(steps);
        self.show_when_slow();
    }

    /// Sets how many are done of how many.
    pub fn at(&self, done: u64, total: u64) {
        self.bar.set_length(total);
        self.bar.set_position(done);
        self.show_when_slow();
    }

    /// Runs `print` with the bar out of the way of what it prints.
    pub fn suspend<T>(&self, print: impl FnOnce() -> T) -> T {
        self.bar.suspend(print)
    }

    fn show_when_slow(&self) {
        if self.bar.is_hidden() && self.start.elapsed().as_secs_f32() >= 1.0 {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// Runs `work` with a bar of `message` counting `unit`s.
pub fn with_bar<T>(message: &str, unit: &str, work: impl FnOnce(&mut kage::progress::Progress) -> T) -> T {
    let bar = Bar::new(0, unit);
    bar.message(message.to_string());
    work(&mut |done, total| {
        bar.at(done as u64, total as u64);
        true
    })
}
