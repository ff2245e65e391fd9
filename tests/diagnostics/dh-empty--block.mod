robot planar {
    dh {   # expect: error[dh-empty]
    }
}
