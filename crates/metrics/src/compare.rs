//! Errors between model variants and a benchmark: seed Appendix A.
//!
//! - **PE**, Eq. A.1: `PE_i = 100 (M_i - M_bm) / M_bm` for a room value M (the seed applies it
//!   to TAI; we apply it to the room row of every metric column).
//! - **MAPE**, Eq. A.2 over N variants: `100/N sum_i |(M_i - M_bm) / M_bm|` (the mean of
//!   |PE_i|; with one variant it is |PE|).
//! - **RMSE**, Eq. A.3: `1/N sum_i sqrt( 1/(H G) sum_j sum_k (x_ijk - x^_jk)^2 )`, over the
//!   G sensors and the H occupied time steps, averaged over the N variants. For two
//!   illuminance matrices x is lux (H = occupied steps of the schedule); for two metric
//!   tables x is the per-sensor metric value and H = 1 (the spatial RMSE of the metric).
//!
//! A zero benchmark makes PE and MAPE undefined: they are reported as NaN (`nan`), never as
//! a made-up number.

use super::report::{Table, fmt_num};
use super::{LuxRows, Schedule};
use crate::error::{Error, Result};
use std::io::{BufRead, Write};

/// Eq. A.1.
pub fn percentage_error(value: f64, benchmark: f64) -> f64 {
    if benchmark == 0.0 {
        f64::NAN
    } else {
        100.0 * (value - benchmark) / benchmark
    }
}

/// Eq. A.2 over the variants' values.
pub fn mape(values: &[f64], benchmark: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values
        .iter()
        .map(|&v| percentage_error(v, benchmark).abs())
        .sum::<f64>()
        / values.len() as f64
}

/// Root mean squared difference of two equally long vectors (one variant's term of Eq. A.3).
pub fn rmse(x: &[f64], benchmark: &[f64]) -> f64 {
    if x.is_empty() {
        return f64::NAN;
    }
    let s: f64 = x
        .iter()
        .zip(benchmark)
        .map(|(a, b)| (a - b) * (a - b))
        .sum();
    (s / x.len() as f64).sqrt()
}

/// One metric's comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    pub metric: String,
    /// The benchmark's room value.
    pub benchmark: f64,
    /// Eq. A.1 per variant.
    pub pe: Vec<f64>,
    /// Eq. A.2.
    pub mape: f64,
    /// Eq. A.3.
    pub rmse: f64,
}

fn room_value(t: &Table, k: usize) -> f64 {
    match &t.room {
        Some(r) => r.get(k).copied().unwrap_or(f64::NAN),
        None if t.sensors.is_empty() => f64::NAN,
        None => {
            t.sensors
                .iter()
                .map(|s| s.get(k).copied().unwrap_or(f64::NAN))
                .sum::<f64>()
                / t.sensors.len() as f64
        }
    }
}

/// Compare metric tables: every column of the benchmark that every variant has.
pub fn compare_tables(
    bench: &Table,
    bench_name: &str,
    variants: &[(String, Table)],
) -> Result<Vec<Comparison>> {
    for (name, v) in variants {
        if v.sensors.len() != bench.sensors.len() {
            return Err(Error::Mismatch(format!(
                "{name} has {} sensors, the benchmark {bench_name} has {}",
                v.sensors.len(),
                bench.sensors.len()
            )));
        }
    }
    let mut out = Vec::new();
    for (k, col) in bench.columns.iter().enumerate() {
        let Some(idx): Option<Vec<usize>> = variants
            .iter()
            .map(|(_, v)| v.columns.iter().position(|c| c == col))
            .collect()
        else {
            continue;
        };
        let b = room_value(bench, k);
        let bcol: Vec<f64> = bench.sensors.iter().map(|s| s[k]).collect();
        let mut pe = Vec::new();
        let mut vals = Vec::new();
        let mut r = 0.0;
        for ((_, v), &j) in variants.iter().zip(&idx) {
            let m = room_value(v, j);
            vals.push(m);
            pe.push(percentage_error(m, b));
            let vcol: Vec<f64> = v.sensors.iter().map(|s| s[j]).collect();
            r += rmse(&vcol, &bcol);
        }
        out.push(Comparison {
            metric: col.clone(),
            benchmark: b,
            pe,
            mape: mape(&vals, b),
            rmse: r / variants.len().max(1) as f64,
        });
    }
    if out.is_empty() {
        return Err(Error::Mismatch(format!(
            "no metric column of {bench_name} is present in every variant"
        )));
    }
    Ok(out)
}

/// Compare illuminance matrices: PE/MAPE of the room TAI (Eq. 2.2) and the RMSE of lux over
/// the occupied steps (Eq. A.3). Streams one row of each matrix at a time.
pub fn compare_matrices<R: BufRead>(
    bench: &mut LuxRows<R>,
    variants: &mut [LuxRows<R>],
    schedule: &Schedule,
) -> Result<Vec<Comparison>> {
    let ncols = bench.ncols();
    for v in variants.iter() {
        if v.ncols() != ncols {
            return Err(Error::Mismatch(format!(
                "{} has {} columns, the benchmark {} has {ncols}",
                v.name(),
                v.ncols(),
                bench.name()
            )));
        }
    }
    if schedule.occupied.len() != ncols || schedule.count() == 0 {
        return Err(Error::Mismatch(format!(
            "{}: {ncols} columns, the schedule has {} steps ({} occupied)",
            bench.name(),
            schedule.occupied.len(),
            schedule.count()
        )));
    }
    let n = variants.len();
    let mut brow = vec![0.0; ncols];
    let mut vrow = vec![0.0; ncols];
    let (mut btai, mut vtai, mut sq) = (0.0, vec![0.0; n], vec![0.0; n]);
    let mut g = 0usize;
    while bench.next_row(&mut brow)? {
        g += 1;
        for (i, v) in variants.iter_mut().enumerate() {
            if !v.next_row(&mut vrow)? {
                return Err(Error::Mismatch(format!(
                    "{} ends after {} rows, the benchmark {} has more",
                    v.name(),
                    g - 1,
                    bench.name()
                )));
            }
            for j in (0..ncols).filter(|&j| schedule.occupied[j]) {
                let d = vrow[j] - brow[j];
                sq[i] += d * d;
                vtai[i] += vrow[j];
            }
        }
        for j in (0..ncols).filter(|&j| schedule.occupied[j]) {
            btai += brow[j];
        }
    }
    for v in variants.iter_mut() {
        if v.next_row(&mut vrow)? {
            return Err(Error::Mismatch(format!(
                "{} has more rows than the benchmark {} ({g})",
                v.name(),
                bench.name()
            )));
        }
    }
    if g == 0 {
        return Err(Error::Usage(format!("{}: no sensor rows", bench.name())));
    }
    let h = schedule.count() as f64;
    let dt = schedule.step_hours;
    let tai = |s: f64| s * dt / (1000.0 * g as f64);
    let b = tai(btai);
    let vals: Vec<f64> = vtai.iter().map(|&s| tai(s)).collect();
    let r = sq.iter().map(|&s| (s / (h * g as f64)).sqrt()).sum::<f64>() / n.max(1) as f64;
    Ok(vec![
        Comparison {
            metric: "TAI_klxh".into(),
            benchmark: b,
            pe: vals.iter().map(|&v| percentage_error(v, b)).collect(),
            mape: mape(&vals, b),
            rmse: f64::NAN,
        },
        Comparison {
            metric: "E_lux".into(),
            benchmark: f64::NAN,
            pe: vec![f64::NAN; n],
            mape: f64::NAN,
            rmse: r,
        },
    ])
}

/// Write the comparison as TSV: `metric benchmark PE_% ... MAPE_% RMSE`, one PE column per
/// variant (named `PE_%` for a single variant, `PE_%:<file>` for several).
pub fn write_comparison(
    w: &mut dyn Write,
    bench_name: &str,
    names: &[String],
    rows: &[Comparison],
) -> Result<()> {
    let io = |e| Error::io("<output>", e);
    writeln!(w, "# benchmark: {bench_name}").map_err(io)?;
    writeln!(w, "# variants (N={}): {}", names.len(), names.join(" ")).map_err(io)?;
    writeln!(
        w,
        "# PE = seed Eq. A.1 on the room value; MAPE = Eq. A.2 over the N variants; RMSE = \
         Eq. A.3 (metric tables: per-sensor values, H = 1; matrices: lux over occupied steps, \
         row E_lux); nan = undefined (zero benchmark or not applicable)"
    )
    .map_err(io)?;
    let pe_cols: Vec<String> = if names.len() == 1 {
        vec!["PE_%".into()]
    } else {
        names.iter().map(|n| format!("PE_%:{n}")).collect()
    };
    writeln!(w, "metric\tbenchmark\t{}\tMAPE_%\tRMSE", pe_cols.join("\t")).map_err(io)?;
    for r in rows {
        let pe: Vec<String> = r.pe.iter().copied().map(fmt_num).collect();
        writeln!(
            w,
            "{}\t{}\t{}\t{}\t{}",
            r.metric,
            fmt_num(r.benchmark),
            pe.join("\t"),
            fmt_num(r.mape),
            fmt_num(r.rmse)
        )
        .map_err(io)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn appendix_a_on_known_vectors() {
        assert_eq!(percentage_error(110.0, 100.0), 10.0);
        assert_eq!(percentage_error(90.0, 100.0), -10.0);
        assert!(percentage_error(1.0, 0.0).is_nan());
        // MAPE of +10 % and -30 %: 20 %.
        assert!((mape(&[110.0, 70.0], 100.0) - 20.0).abs() < 1e-12);
        // RMSE of differences (3, -4): sqrt(25/2).
        assert!((rmse(&[4.0, 1.0], &[1.0, 5.0]) - 12.5f64.sqrt()).abs() < 1e-12);
    }

    fn table(cols: &[&str], rows: &[&[f64]]) -> Table {
        let sensors: Vec<Vec<f64>> = rows.iter().map(|r| r.to_vec()).collect();
        let n = sensors.len() as f64;
        let room = (0..cols.len())
            .map(|k| sensors.iter().map(|s| s[k]).sum::<f64>() / n)
            .collect();
        Table {
            columns: cols.iter().map(|c| c.to_string()).collect(),
            sensors,
            room: Some(room),
        }
    }

    #[test]
    fn tables_by_hand() {
        let b = table(&["TAI_klxh", "DA"], &[&[1.0, 40.0], &[3.0, 60.0]]);
        let v1 = table(&["DA", "TAI_klxh"], &[&[50.0, 2.0], &[70.0, 4.0]]);
        let v2 = table(&["TAI_klxh", "DA"], &[&[1.0, 40.0], &[1.0, 60.0]]);
        let rows = compare_tables(&b, "b", &[("v1".into(), v1), ("v2".into(), v2)]).unwrap();
        let tai = &rows[0];
        // room TAI: bench 2, v1 3 (+50 %), v2 1 (-50 %).
        assert_eq!(tai.benchmark, 2.0);
        assert_eq!(tai.pe, vec![50.0, -50.0]);
        assert_eq!(tai.mape, 50.0);
        // RMSE: v1 diffs (1, 1) -> 1; v2 diffs (0, -2) -> sqrt(2); mean.
        assert!((tai.rmse - (1.0 + 2f64.sqrt()) / 2.0).abs() < 1e-12);
        let da = &rows[1];
        assert_eq!(da.pe, vec![20.0, 0.0]);
        assert_eq!(da.rmse, 5.0);
        let short = table(&["DA"], &[&[1.0]]);
        assert!(compare_tables(&b, "b", &[("s".into(), short)]).is_err());
    }
}
