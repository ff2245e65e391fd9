# A name longer than 64 characters: it would become a file name (mod3_<name>.urdf.xacro) and a ROS package name.
robot farm {
    chain H1 - L4(port=45deg) - L1
    pose home_position_of_the_farm_arm_when_it_is_parked_next_to_the_potting_bench (0, 0, 0) deg   # expect: error[invalid-name]
}
