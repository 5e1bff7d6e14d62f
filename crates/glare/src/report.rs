//! evalglare 3.06's output lines (`main` of `src/util/evalglare.c`; notes §9.5), so that
//! scripts parsing evalglare's output parse ours. All numbers use C's `%f` (6 decimals),
//! the source solid angle `%.10f`.
//!
//! - default: `dgp,dgi,ugr,vcp,cgi,Lveil: <6 values>` followed by two blanks (evalglare's
//!   format string ends in `"  \n"`);
//! - `-d`: the header `<n> No pixels x-pos y-pos L_s Omega_s Posindx L_b L_t E_v Edir
//!   Max_Lum Sigma xdir ydir zdir Eglare Lveil_cie teta glare_zone r_contrast r_dgp`, one
//!   line per source (ending in a blank; y-pos from the top; with no source a single line of
//!   zeros carrying L_b, L_t, E_v, E_dir, Max_Lum), then `dgp,av_lum,E_v,lum_backg,E_v_dir,
//!   dgi,ugr,vcp,cgi,lum_sources,omega_sources,Lveil,Lveil_cie,dgr,ugp,ugr_exp,dgi_mod,
//!   av_lum_pos,av_lum_pos2,med_lum,med_lum_pos,med_lum_pos2,ugp2:` and 23 values;
//! - `-V`: E_v alone.
//!
//! The detection method and threshold are never written to standard output (that would
//! break evalglare-compatible parsing); [`method_line`] is what `rglare` prints on stderr.

use super::{Evaluation, Method, PositionStats};

/// The default one-line output.
pub fn default_line(e: &Evaluation) -> String {
    let m = &e.metrics;
    format!(
        "dgp,dgi,ugr,vcp,cgi,Lveil: {:.6} {:.6} {:.6} {:.6} {:.6} {:.6}  \n",
        m.dgp, m.dgi, m.ugr, m.vcp, m.cgi, m.lveil
    )
}

/// `-V`: vertical illuminance.
pub fn ev_line(e_v: f64) -> String {
    format!("{e_v:.6}\n")
}

/// The detailed (`-d`) output (of an evaluation made with [`super::Options::position_stats`]:
/// without, its five values print as NaN).
pub fn detailed(e: &Evaluation) -> String {
    let mut s = format!(
        "{} No pixels x-pos y-pos L_s Omega_s Posindx L_b L_t E_v Edir Max_Lum Sigma xdir ydir zdir Eglare Lveil_cie teta glare_zone r_contrast r_dgp\n",
        e.sources.len()
    );
    if e.sources.is_empty() {
        s += &format!(
            "0 {:.6} {:.6} {:.6} {:.6} {:.10} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6}{}\n",
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            e.lum_backg,
            e.lum_task as f32,
            e.e_v,
            e.e_dir,
            e.abs_max,
            " 0.000000".repeat(11)
        );
    }
    for (k, r) in e.sources.iter().enumerate() {
        s += &format!(
            "{} {:.6} {:.6} {:.6} {:.6} {:.10} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} 0 {:.6} {:.6} \n",
            k + 1,
            r.npix,
            r.x,
            r.y,
            r.lum,
            r.omega,
            r.pos,
            e.lum_backg,
            e.lum_task as f32,
            e.e_v,
            e.e_dir,
            e.abs_max,
            r.sigma_deg,
            r.dir[0],
            r.dir[1],
            r.dir[2],
            r.eglare,
            r.lveil_cie,
            r.teta,
            r.r_contrast,
            r.r_dgp
        );
    }
    let m = &e.metrics;
    let nan = f64::NAN;
    let ps = e.position.unwrap_or(PositionStats {
        av_lum_pos: nan,
        av_lum_pos2: nan,
        med_lum: nan,
        med_lum_pos: nan,
        med_lum_pos2: nan,
    });
    let v = [
        m.dgp,
        e.avlum,
        e.e_v,
        e.lum_backg,
        e.e_dir,
        m.dgi,
        m.ugr,
        m.vcp,
        m.cgi,
        e.lum_sources,
        e.omega_sources,
        m.lveil,
        e.lveil_cie,
        m.dgr,
        m.ugp,
        m.ugr_exp,
        m.dgi_mod,
        ps.av_lum_pos,
        ps.av_lum_pos2,
        ps.med_lum,
        ps.med_lum_pos,
        ps.med_lum_pos2,
        m.ugp2,
    ];
    s += "dgp,av_lum,E_v,lum_backg,E_v_dir,dgi,ugr,vcp,cgi,lum_sources,omega_sources,Lveil,Lveil_cie,dgr,ugp,ugr_exp,dgi_mod,av_lum_pos,av_lum_pos2,med_lum,med_lum_pos,med_lum_pos2,ugp2:";
    for x in v {
        // + 0.0 turns −0 (an empty f64 sum) into 0, which C prints without a sign
        s += &format!(" {:.6}", x + 0.0);
    }
    s.push('\n');
    s
}

/// One stderr line naming the detection method and threshold.
pub fn method_line(name: &str, e: &Evaluation, radius: f64, peaks: Option<f64>) -> String {
    let how = match e.method {
        Method::Absolute => "absolute".to_string(),
        Method::TaskMultiple(f) => format!("{f} x task luminance {:.3} cd/m2", e.lum_task),
        Method::MeanMultiple(f) => format!("{f} x mean luminance {:.3} cd/m2", e.lum_task),
    };
    let peak = match peaks {
        Some(l) => format!("peak extraction above {l} cd/m2"),
        None => "no peak extraction".into(),
    };
    format!(
        "rglare: {name}: glare sources above {:.3} cd/m2 ({how}), search radius {radius} rad, {peak}; {} source(s)",
        e.threshold,
        e.sources.len()
    )
}
