robot farm {
    chain H1 - L4(port=45deg) - L1
    pose home (0, 30) deg   # expect: error[pose-arity] pose 'home' has 2 values; robot 'farm' has 3 joints
}
