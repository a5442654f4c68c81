//! `kage sweep --technique asm`: adaptive shadow maps at several budgets against conventional
//! maps of several sizes over the scene's camera walkthrough, measured as `kage bench asm`
//! measures them (error against the ray-traced hard-shadow reference, GPU time side by side,
//! shadow memory), written as the sweep's CSV and chart, with the picks.
use super::{write_outputs, SweepArgs, Terms, FRAME_TIME};
use crate::bench::asm::report::{points, ERROR_AXIS};
use crate::bench::asm::{measure, AsmBenchArgs, DEFAULT_CONFIGS};
use crate::chart;
use anyhow::Result;
use std::fmt::Write as _;

pub fn run(args: &SweepArgs) -> Result<()> {
    let configs =
        if args.only.is_empty() { DEFAULT_CONFIGS.map(String::from).to_vec() } else { args.only.clone() };
    let scene = args.scene.as_deref().unwrap_or("asm");
    let bench =
        AsmBenchArgs::for_sweep(scene, configs, args.frames, args.size, args.out.clone(), args.gpu.clone());
    let measured = measure(&bench)?;
    measured.print();

    let mut csv = String::from(
        "scene,technique,parameter,value,error_mean,error_max,error_at_rest,flips_mean,frame_ms,ratio,memory_mb\n",
    );
    let optional = |v: Option<f64>| v.map_or_else(String::new, |v| format!("{v:.6}"));
    for (c, s) in measured.configs.iter().zip(&measured.summaries) {
        writeln!(
            csv,
            "{},{},{},{},{:.6},{:.6},{},{},{:.4},{:.4},{}",
            measured.scene,
            c.kind,
            c.parameter,
            c.value,
            s.error_mean,
            s.error_max,
            optional(s.error_at_rest),
            optional(s.flips_mean),
            s.frame_ms,
            s.ratio,
            s.shadow_bytes.map_or_else(String::new, |b| format!("{:.2}", b as f64 / (1 << 20) as f64)),
        )
        .expect("writing to a String");
    }
    write_outputs(
        args,
        &measured.scene,
        &csv,
        (&measured.title, &chart::frame_time_against(ERROR_AXIS)),
        &points(&measured.configs, &measured.summaries),
        args.max_ms,
        &Terms { metric: "mismatch", unit: FRAME_TIME },
    )
}
