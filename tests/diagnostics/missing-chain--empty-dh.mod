# corpus-xfail: an empty dh table (or one whose rows are all incomplete) yields a robot with no units and no diagnostic; `modc lint` passes and `modc FILE -o OUT` crashes with IndexError in kinematics
robot planar {   # expect: error[missing-chain]
    dh {
    }
}
