//! A progress bar for the engine's long work (`kage::progress::Progress`): hidden until the
//! work has lasted a second, so quick work prints nothing.
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::time::Instant;

/// Runs `work` with a bar of `message` counting `unit`s, cleared when it ends.
pub fn with_bar<T>(message: &str, unit: &str, work: impl FnOnce(&mut kage::progress::Progress) -> T) -> T {
    let template = format!("{{msg}} [{{bar:30}}] {{pos}}/{{len}} {unit}, {{elapsed}} elapsed, {{eta}} left");
    let bar =
        ProgressBar::hidden().with_style(ProgressStyle::with_template(&template).expect("static template"));
    bar.set_message(message.to_string());
    let start = Instant::now();
    let result = work(&mut |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        if start.elapsed().as_secs_f32() >= 1.0 && bar.is_hidden() {
            bar.set_draw_target(ProgressDrawTarget::stderr());
        }
        true
    });
    bar.finish_and_clear();
    result
}
