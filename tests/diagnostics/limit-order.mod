robot farm {
    chain H1 - L4(port=45deg) - L1
    limit joint_1 (90, -90) deg   # expect: error[limit-order]
}
