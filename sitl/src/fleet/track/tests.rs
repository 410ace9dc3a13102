use super::*;
use crate::fleet::PX4_STEP_US;
use crate::fleet::file;

/// A quad X at home and a hexa X 4 m east of it, both PX4s.
const QUAD_AND_HEXA: &str = r#"
[[vehicle]]
autopilot = "px4"
instance = 0
[[vehicle]]
autopilot = "px4"
instance = 1
position = [4.0, 0.0]
frame = "hexa_x"
"#;

fn track_path(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("flyloop-{}-{name}.csv", std::process::id()))
}

#[test]
fn a_row_per_vehicle_each_interval_with_its_name_sysid_connection_and_state() {
    let spec = file::parse(QUAD_AND_HEXA, Path::new(".")).unwrap();
    let mut fleet = Fleet::new(&spec, 3, PX4_STEP_US).unwrap();
    let path = track_path("fleet-track");
    let mut track = FleetTrack::create(&path, 8_000, &fleet).unwrap();
    track.record(&fleet).unwrap();
    fleet.px4_connected(1);
    // The hexa's PX4 runs free (nobody in lockstep): the world steps 4 ms at a time.
    for _ in 0..5 {
        fleet.advance(true).unwrap();
        track.record(&fleet).unwrap();
    }
    track.flush().unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0],
        "vehicle,sysid,connection,time_us,north,east,down,vn,ve,vd,roll,pitch,yaw,\
         m0,m1,m2,m3,m4,m5,grounded,p,q,r,faults"
    );
    let rows: Vec<Vec<&str>> = lines[1..].iter().map(|l| l.split(',').collect()).collect();
    // t = 0, 8, 16 ms (rows every 8 ms of world time), each with both vehicles.
    let heads: Vec<[&str; 4]> = rows.iter().map(|r| [r[0], r[1], r[2], r[3]]).collect();
    assert_eq!(
        heads,
        [
            ["px4-000", "1", "0", "0"],
            ["px4-001", "2", "0", "0"],
            ["px4-000", "1", "0", "8000"],
            ["px4-001", "2", "1", "8000"],
            ["px4-000", "1", "0", "16000"],
            ["px4-001", "2", "1", "16000"],
        ]
    );
    for r in &rows {
        assert_eq!(r.len(), 24, "{r:?}");
    }
    // The quad's last two motor columns are empty; the hexa's are not.
    assert_eq!((rows[0][17], rows[0][18]), ("", ""));
    assert_eq!((rows[1][17], rows[1][18]), ("0.0000", "0.0000"));
    // East of home, standing on its gear, level.
    assert_eq!((rows[0][5], rows[1][5]), ("0.0000", "4.0000"));
    assert_eq!(rows[1][19], "1", "grounded");
}
