robot arm {
    chain H1 - L4 - L3
    target a at (0.3, 0, 0.2) m rpy (0, 90, 0) deg within 0 mm, 2 deg   # expect: error[nonpositive-size] the position tolerance of target 'a' must be positive, got 0 mm
}
