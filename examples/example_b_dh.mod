# Paper section 5.1, Example B given as its DH table: modc picks the modules (paper section
# 4.2, the policy in the README) -> H1-H4-H4-L2-L2-L2, the published sequence. `fit-links`
# prints the two link modules 329.7 mm long so that a = 0.3 m is realised exactly.
# The paper gives alpha = 2.36 rad (135.2°); the ports are set in 15° steps, so 135° is written
# here (examples/example_b.csv keeps 2.36 rad: dh2mod then warns about the rounding).
# `modc dh examples/example_b_dh.mod` shows requested and realised DH side by side.
robot example_b_dh {
    dh fit-links {
        row a=0m, alpha=-90deg, d=0.148m
        row a=0.3m, alpha=135deg, d=0m
        row a=0.3m, alpha=135deg, d=0m
        row a=0m, alpha=-90deg, d=0.148m
        row a=0m, alpha=-90deg, d=0.148m
        row a=0m, alpha=0deg, d=0.075m
    }
}
