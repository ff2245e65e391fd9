# The Mark-2 modules turn -170..170 deg; a wider limit is a warning and the library's range is used.
robot farm {
    chain H1 - L4(port=45deg) - L1
    limit joint_3 (-180, 180) deg   # expect: warning[limit-exceeds-hardware] limit for joint_3 (-180deg..180deg) is wider than the module's range -170deg..170deg
}
