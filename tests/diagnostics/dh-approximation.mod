# A DH table is realised with fixed-size modules; the note says how closely.
robot example_a {   # expect: note[dh-approximation] robot 'example_a' realises its DH table within |da| <= 109.7 mm, |dalpha| <= 0.00deg, |dd| <= 221.0 mm
    dh {
        row a=0 m,   alpha=-90deg, d=0.148 m
        row a=0.3 m, alpha=15deg,  d=0 m
        row a=0.3 m, alpha=0deg,   d=0 m
        row a=0 m,   alpha=0deg,   d=0.075 m
    }
}
