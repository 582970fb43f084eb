// The unit methods/pairs_pch.hpp is precompiled with (cstab_pch in
// cmake/cstab_catalog.cmake); it has no code of its own.
