# Paper Example A's alpha = 0.26 rad (14.9 deg): the port is set in 15 deg steps, so it is rounded.
robot example_a {   # expect: note[dh-approximation] robot 'example_a' realises its DH table within |da| <= 0.0 mm, |dalpha| <= 0.10deg, |dd| <= 221.0 mm
    dh fit-links {
        row a=0 m,   alpha=-90deg,   d=0.148 m
        row a=0.3 m, alpha=0.26 rad, d=0 m   # expect: warning[twist-rounded] DH row 2: alpha 0.26 rad (14.8969deg) is realised as 15deg (port of unit 2)
        row a=0.3 m, alpha=0deg,     d=0 m
        row a=0 m,   alpha=0deg,     d=0.075 m
    }
}
