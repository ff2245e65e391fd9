# A robot is given either as a chain or as a DH table (converted into a chain), not both.
robot example_b {
    chain H1 - H4 - H4 - L2 - L2 - L2
    dh {   # expect: error[chain-and-dh] robot 'example_b' has both a chain and a dh table
        row a=0 m,   alpha=-90deg, d=0.148 m
        row a=0.3 m, alpha=135deg, d=0 m
        row a=0 m,   alpha=0deg,   d=0.075 m
    }
}
