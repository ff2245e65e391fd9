# Paper Example A's alpha = 0.26 rad (14.9 deg): the port is set in 15 deg steps, so it is rounded.
robot example_a {   # expect: note[dh-approximation]
    dh fit-links {
        row a=0 m,   alpha=-90deg,   d=0.148 m
        row a=0.3 m, alpha=0.26 rad, d=0 m   # expect: warning[twist-rounded]
        row a=0.3 m, alpha=0deg,     d=0 m
        row a=0 m,   alpha=0deg,     d=0.075 m
    }
}
