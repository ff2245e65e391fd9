robot farm {
    chain H1 - L4(port=45deg) - L1
    limit joint_4 (-90, 90) deg   # expect: error[unknown-joint] robot 'farm' has no joint 'joint_4'
}
