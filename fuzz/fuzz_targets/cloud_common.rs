//! What every point-cloud target checks after a successful read: the per-point arrays the
//! pipeline indexes together have one entry per point, station indices are in range when
//! the file gives stations (without them, `--stations` may supply them later), and
//! `PointCloud::check` (the first thing `rrecon` does) answers Ok or Err.
use rdaylight::recon::PointCloud;

pub fn check(cloud: &PointCloud) {
    let n = cloud.points.len();
    if let Some(v) = &cloud.normals {
        assert_eq!(v.len(), n, "normals per point");
    }
    if let Some(v) = &cloud.colors {
        assert_eq!(v.len(), n, "colours per point");
    }
    if let Some(v) = &cloud.station_of {
        assert_eq!(v.len(), n, "stations per point");
        let n = cloud.stations.len();
        assert!(
            n == 0 || v.iter().all(|&s| usize::from(s) < n),
            "station index"
        );
    }
    let _ = cloud.check("fuzz");
}
