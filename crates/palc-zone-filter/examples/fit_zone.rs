// Fit a driver's perceived safe zone from labelled samples in CSV and turn it into
// lateral bounds for each step of a planning horizon (paper Eqs. 1-8 and 27-32).
//
// Run with `cargo run -p palc-zone-filter --example fit_zone`; it prints the bounds
// as CSV (`step,s,status,l_min,l_max`).

use palc_zone_filter::{
    BoundsConfig, FeatureInput, FeatureSet, Label, Sample, StepBounds, StepScene, ZoneConfig,
    ZoneModel, features, lateral_bounds,
};

// Three recorded lane changes that the driver took over, one CSV row per position:
// driven by the system (y = 1, not taken over) or by the driver after the takeover
// (y = 0, here 1.6 m further left). The preceding vehicle is 36, 30 and 24 m ahead in
// the ego lane, the adjacent vehicle 6, 10 and 14 m ahead on the target lane
// (l = 3.5 m). Read your own file with `std::fs::read_to_string`.
const SAMPLES: &str = "\
ego_s,ego_l,ego_speed,preceding_s,preceding_l,adjacent_s,adjacent_l,y
0.0,-0.5,20.0,36.0,0.0,6.0,3.5,1
0.0,1.1,20.0,36.0,0.0,6.0,3.5,0
4.0,-0.3,20.0,40.0,0.0,10.0,3.5,1
4.0,1.3,20.0,40.0,0.0,10.0,3.5,0
8.0,-0.1,20.0,44.0,0.0,14.0,3.5,1
8.0,1.5,20.0,44.0,0.0,14.0,3.5,0
12.0,0.1,20.0,48.0,0.0,18.0,3.5,1
12.0,1.7,20.0,48.0,0.0,18.0,3.5,0
16.0,0.3,20.0,52.0,0.0,22.0,3.5,1
16.0,1.9,20.0,52.0,0.0,22.0,3.5,0
20.0,0.5,20.0,56.0,0.0,26.0,3.5,1
20.0,2.1,20.0,56.0,0.0,26.0,3.5,0
24.0,-0.5,20.0,54.0,0.0,34.0,3.5,1
24.0,1.1,20.0,54.0,0.0,34.0,3.5,0
28.0,-0.3,20.0,58.0,0.0,38.0,3.5,1
28.0,1.3,20.0,58.0,0.0,38.0,3.5,0
32.0,-0.1,20.0,62.0,0.0,42.0,3.5,1
32.0,1.5,20.0,62.0,0.0,42.0,3.5,0
36.0,0.1,20.0,66.0,0.0,46.0,3.5,1
36.0,1.7,20.0,66.0,0.0,46.0,3.5,0
40.0,0.3,20.0,70.0,0.0,50.0,3.5,1
40.0,1.9,20.0,70.0,0.0,50.0,3.5,0
44.0,0.5,20.0,74.0,0.0,54.0,3.5,1
44.0,2.1,20.0,74.0,0.0,54.0,3.5,0
48.0,-0.5,20.0,72.0,0.0,62.0,3.5,1
48.0,1.1,20.0,72.0,0.0,62.0,3.5,0
52.0,-0.3,20.0,76.0,0.0,66.0,3.5,1
52.0,1.3,20.0,76.0,0.0,66.0,3.5,0
56.0,-0.1,20.0,80.0,0.0,70.0,3.5,1
56.0,1.5,20.0,80.0,0.0,70.0,3.5,0
60.0,0.1,20.0,84.0,0.0,74.0,3.5,1
60.0,1.7,20.0,84.0,0.0,74.0,3.5,0
64.0,0.3,20.0,88.0,0.0,78.0,3.5,1
64.0,1.9,20.0,88.0,0.0,78.0,3.5,0
68.0,0.5,20.0,92.0,0.0,82.0,3.5,1
68.0,2.1,20.0,92.0,0.0,82.0,3.5,0
";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // CSV rows to labelled samples in the paper's feature space (Eq. 1).
    let mut samples = Vec::new();
    for (line, row) in SAMPLES.lines().enumerate().skip(1) {
        let line = line + 1;
        let fields: Vec<&str> = row.split(',').map(str::trim).collect();
        let (y, numbers) = fields.split_last().ok_or("empty line")?;
        let v = numbers
            .iter()
            .map(|x| x.parse::<f64>())
            .collect::<Result<Vec<f64>, _>>()
            .map_err(|e| format!("line {line}: {e}"))?;
        if v.len() != 7 {
            return Err(format!("line {line}: expected 8 columns, found {}", fields.len()).into());
        }
        let input = FeatureInput {
            ego_s: v[0],
            ego_l: v[1],
            ego_speed: v[2],
            preceding: [v[3], v[4]],
            adjacent: [v[5], v[6]],
        };
        let label = match *y {
            "1" => Label::Safe,
            "0" => Label::Unsafe,
            other => return Err(format!("line {line}: y = {other} must be 0 or 1").into()),
        };
        samples.push(Sample::new(features(FeatureSet::Paper, &input)?, label));
    }

    // Gaussian discriminant analysis with a shared covariance (Eqs. 3-8).
    let model = ZoneModel::fit(ZoneConfig::default(), &samples)?;
    if !model.is_informative() {
        return Err("the samples do not separate the classes; record more takeovers".into());
    }

    // The predicted scene at each step of a 3 s horizon (dt = 0.5 s): the ego at
    // 20 m/s, the preceding vehicle slower (18 m/s), the adjacent one faster (22 m/s).
    let dt = 0.5;
    let scenes: Vec<StepScene> = (0..=6)
        .map(|i| {
            let t = dt * i as f64;
            StepScene {
                ego_s: 20.0 * t,
                reference_l: 0.0,
                ego_speed: 20.0,
                preceding: [30.0 + 18.0 * t, 0.0],
                adjacent: [10.0 + 22.0 * t, 3.5],
            }
        })
        .collect();

    // The safe interval around the reference at each step (Eq. 22's l_min,i, l_max,i).
    let bounds = lateral_bounds(&model, &scenes, &BoundsConfig::default())?;
    println!("step,s,status,l_min,l_max");
    for (i, (scene, b)) in scenes.iter().zip(&bounds).enumerate() {
        match *b {
            StepBounds::Bounded { min, max } => {
                println!("{i},{:.1},bounded,{min:.3},{max:.3}", scene.ego_s)
            }
            StepBounds::Unconstrained => println!("{i},{:.1},unconstrained,,", scene.ego_s),
            StepBounds::NoSafeInterval => println!("{i},{:.1},no_safe_interval,,", scene.ego_s),
        }
    }
    Ok(())
}
