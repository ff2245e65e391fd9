robot farm {
    chain H1 - L4(port=45deg) - L1
    limit joint_1 (90, -90) deg   # expect: error[limit-order] limit for joint_1: lower 90deg is not below upper -90deg
}
