# The chain was left out: reported at the robot's name.
robot cellarm {   # expect: error[missing-chain] robot 'cellarm' has no chain
    box shelf size (0.6, 0.4, 0.02) m at (0.3, 0, 0.25) m
    target p1 at (-0.24, -0.23, 0.585) m
}
