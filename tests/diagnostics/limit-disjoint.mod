robot farm {
    chain H1 - L4(port=45deg) - L1
    limit joint_2 (171, 175) deg   # expect: error[limit-disjoint] limit for joint_2 (171deg..175deg) lies outside the module's range -170deg..170deg
}
