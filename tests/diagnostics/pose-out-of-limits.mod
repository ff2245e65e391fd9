robot farm {
    chain H1 - L4(port=45deg) - L1
    limit joint_2 (-90, 90) deg
    pose reach (0, 120, 0) deg   # expect: error[pose-out-of-limits] pose 'reach': joint_2 = 120deg is outside its limits -90deg..90deg
}
