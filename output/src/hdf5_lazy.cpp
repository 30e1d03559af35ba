// The HDF5 library, loaded on the first HDF5 call of the process, so that a run without
// snapshots (and --help, a check) starts without it and the MPI libraries it brings. The
// functions and type globals that output.cpp uses are defined here, hidden from the modules
// (CMakeLists.txt compiles this file with hidden visibility, so the program does not export
// them): each forwards to the library's own, found by dlsym; each type global is copied from the
// library's after its H5open(), which the hdf5.h macros call before reading one. The library is
// the one deal.II links (SMPM_HDF5_LIBRARY, set by CMakeLists.txt), so a process that also has
// the far field holds one HDF5.
//
// A library that cannot be loaded is a std::runtime_error naming it and the loader's reason,
// thrown from the HDF5 call that needed it (the snapshot writer reports it as its own error).
#include <hdf5.h>

#include <dlfcn.h>

#include <stdexcept>
#include <string>

#ifndef SMPM_HDF5_LIBRARY
#error "SMPM_HDF5_LIBRARY: the HDF5 shared library to load (CMakeLists.txt sets it)"
#endif

// Every function of hdf5.h that output.cpp calls (directly or through hdf5.h's macros).
#define SMPM_H5_FUNCTIONS(X)                                                                      \
  X(H5open) X(H5check_version) X(H5Eset_auto2) X(H5Eclear2) X(H5Ewalk2) X(H5Fcreate) X(H5Fopen) \
  X(H5Fflush) X(H5Fclose) X(H5Pcreate) X(H5Pclose) X(H5Pset_file_locking) X(H5Pset_chunk)       \
  X(H5Pset_deflate) X(H5Pset_shuffle) X(H5Gcreate2)                                              \
  X(H5Gopen2) X(H5Gclose) X(H5Lexists) X(H5Ldelete) X(H5Literate) X(H5Screate)                  \
  X(H5Screate_simple) X(H5Sget_simple_extent_dims) X(H5Sclose) X(H5Dcreate2) X(H5Dopen2)        \
  X(H5Dwrite) X(H5Dget_space) X(H5Dclose) X(H5Acreate2) X(H5Aopen) X(H5Aexists) X(H5Awrite)     \
  X(H5Aread) X(H5Aget_type) X(H5Aclose) X(H5Tcopy) X(H5Tset_size) X(H5Tget_size) X(H5Tclose)   \
  X(H5Sselect_hyperslab) X(H5Sselect_none) X(H5Pset_alloc_time) SMPM_H5_MPI_FUNCTIONS(X)

// Writing one file from several processes (MPI-IO), in HDF5's MPI flavour.
#ifdef H5_HAVE_PARALLEL
#define SMPM_H5_MPI_FUNCTIONS(X) X(H5Pset_fapl_mpio) X(H5Pset_dxpl_mpio)
#else
#define SMPM_H5_MPI_FUNCTIONS(X)
#endif

// The type and property-class globals those macros read.
#define SMPM_H5_GLOBALS(X)                                                                         \
  X(H5T_NATIVE_DOUBLE_g) X(H5T_IEEE_F64LE_g) X(H5T_STD_I64LE_g) X(H5T_NATIVE_INT64_g)              \
  X(H5T_STD_I32LE_g) X(H5T_NATIVE_INT32_g) X(H5T_STD_U32LE_g) X(H5T_NATIVE_UINT32_g) X(H5T_C_S1_g) \
  X(H5P_CLS_FILE_ACCESS_ID_g) X(H5P_CLS_DATASET_CREATE_ID_g) X(H5P_CLS_DATASET_XFER_ID_g)

namespace {

struct Library {
#define SMPM_H5_MEMBER(name) decltype(&::name) name = nullptr;
  SMPM_H5_FUNCTIONS(SMPM_H5_MEMBER)
#undef SMPM_H5_MEMBER
#define SMPM_H5_MEMBER(name) const hid_t* name = nullptr;
  SMPM_H5_GLOBALS(SMPM_H5_MEMBER)
#undef SMPM_H5_MEMBER
};

Library load() {
  const char* path = SMPM_HDF5_LIBRARY;
  void* h = dlopen(path, RTLD_LAZY | RTLD_LOCAL);
  if (!h) {
    const char* e = dlerror();
    throw std::runtime_error(std::string("cannot load the HDF5 library ") + path + ": " +
                             (e ? e : "unknown reason"));
  }
  Library lib;
  auto sym = [&](const char* name) {
    void* s = dlsym(h, name);
    if (!s)
      throw std::runtime_error(std::string("the HDF5 library ") + path + " has no " + name +
                               " (another HDF5 version than the one silentmpm was built with)");
    return s;
  };
#define SMPM_H5_LOAD(name) lib.name = reinterpret_cast<decltype(lib.name)>(sym(#name));
  SMPM_H5_FUNCTIONS(SMPM_H5_LOAD)
  SMPM_H5_GLOBALS(SMPM_H5_LOAD)
#undef SMPM_H5_LOAD
  return lib;
}

const Library& lib() {
  static const Library l = load();  // retried on the next call if it threw
  return l;
}

}  // namespace

extern "C" {

// The globals, as the program sees them: filled from the library's by H5open().
#define SMPM_H5_DEFINE(name) hid_t name = -1;
SMPM_H5_GLOBALS(SMPM_H5_DEFINE)
#undef SMPM_H5_DEFINE

herr_t H5open(void) {
  const herr_t r = lib().H5open();
  if (r >= 0) {
#define SMPM_H5_COPY(name) name = *lib().name;
    SMPM_H5_GLOBALS(SMPM_H5_COPY)
#undef SMPM_H5_COPY
  }
  return r;
}
herr_t H5check_version(unsigned majnum, unsigned minnum, unsigned relnum) {
  return lib().H5check_version(majnum, minnum, relnum);
}
herr_t H5Eset_auto2(hid_t estack_id, H5E_auto2_t func, void* client_data) {
  return lib().H5Eset_auto2(estack_id, func, client_data);
}
herr_t H5Eclear2(hid_t err_stack) { return lib().H5Eclear2(err_stack); }
herr_t H5Ewalk2(hid_t err_stack, H5E_direction_t direction, H5E_walk2_t func, void* client_data) {
  return lib().H5Ewalk2(err_stack, direction, func, client_data);
}
hid_t H5Fcreate(const char* filename, unsigned flags, hid_t fcpl_id, hid_t fapl_id) {
  return lib().H5Fcreate(filename, flags, fcpl_id, fapl_id);
}
hid_t H5Fopen(const char* filename, unsigned flags, hid_t fapl_id) {
  return lib().H5Fopen(filename, flags, fapl_id);
}
herr_t H5Fflush(hid_t object_id, H5F_scope_t scope) { return lib().H5Fflush(object_id, scope); }
herr_t H5Fclose(hid_t file_id) { return lib().H5Fclose(file_id); }
hid_t H5Pcreate(hid_t cls_id) { return lib().H5Pcreate(cls_id); }
herr_t H5Pclose(hid_t plist_id) { return lib().H5Pclose(plist_id); }
herr_t H5Pset_file_locking(hid_t fapl_id, hbool_t use_file_locking, hbool_t ignore_when_disabled) {
  return lib().H5Pset_file_locking(fapl_id, use_file_locking, ignore_when_disabled);
}
herr_t H5Pset_chunk(hid_t plist_id, int ndims, const hsize_t dim[]) {
  return lib().H5Pset_chunk(plist_id, ndims, dim);
}
herr_t H5Pset_deflate(hid_t plist_id, unsigned level) { return lib().H5Pset_deflate(plist_id, level); }
herr_t H5Pset_shuffle(hid_t plist_id) { return lib().H5Pset_shuffle(plist_id); }
herr_t H5Pset_alloc_time(hid_t plist_id, H5D_alloc_time_t alloc_time) {
  return lib().H5Pset_alloc_time(plist_id, alloc_time);
}
hid_t H5Gcreate2(hid_t loc_id, const char* name, hid_t lcpl_id, hid_t gcpl_id, hid_t gapl_id) {
  return lib().H5Gcreate2(loc_id, name, lcpl_id, gcpl_id, gapl_id);
}
hid_t H5Gopen2(hid_t loc_id, const char* name, hid_t gapl_id) {
  return lib().H5Gopen2(loc_id, name, gapl_id);
}
herr_t H5Gclose(hid_t group_id) { return lib().H5Gclose(group_id); }
htri_t H5Lexists(hid_t loc_id, const char* name, hid_t lapl_id) {
  return lib().H5Lexists(loc_id, name, lapl_id);
}
herr_t H5Ldelete(hid_t loc_id, const char* name, hid_t lapl_id) {
  return lib().H5Ldelete(loc_id, name, lapl_id);
}
herr_t H5Literate(hid_t grp_id, H5_index_t idx_type, H5_iter_order_t order, hsize_t* idx,
                  H5L_iterate_t op, void* op_data) {
  return lib().H5Literate(grp_id, idx_type, order, idx, op, op_data);
}
hid_t H5Screate(H5S_class_t type) { return lib().H5Screate(type); }
hid_t H5Screate_simple(int rank, const hsize_t dims[], const hsize_t maxdims[]) {
  return lib().H5Screate_simple(rank, dims, maxdims);
}
int H5Sget_simple_extent_dims(hid_t space_id, hsize_t dims[], hsize_t maxdims[]) {
  return lib().H5Sget_simple_extent_dims(space_id, dims, maxdims);
}
herr_t H5Sclose(hid_t space_id) { return lib().H5Sclose(space_id); }
herr_t H5Sselect_hyperslab(hid_t space_id, H5S_seloper_t op, const hsize_t start[],
                           const hsize_t stride[], const hsize_t count[], const hsize_t block[]) {
  return lib().H5Sselect_hyperslab(space_id, op, start, stride, count, block);
}
herr_t H5Sselect_none(hid_t space_id) { return lib().H5Sselect_none(space_id); }
#ifdef H5_HAVE_PARALLEL
herr_t H5Pset_fapl_mpio(hid_t fapl_id, MPI_Comm comm, MPI_Info info) {
  return lib().H5Pset_fapl_mpio(fapl_id, comm, info);
}
herr_t H5Pset_dxpl_mpio(hid_t dxpl_id, H5FD_mpio_xfer_t xfer_mode) {
  return lib().H5Pset_dxpl_mpio(dxpl_id, xfer_mode);
}
#endif
hid_t H5Dcreate2(hid_t loc_id, const char* name, hid_t type_id, hid_t space_id, hid_t lcpl_id,
                 hid_t dcpl_id, hid_t dapl_id) {
  return lib().H5Dcreate2(loc_id, name, type_id, space_id, lcpl_id, dcpl_id, dapl_id);
}
hid_t H5Dopen2(hid_t loc_id, const char* name, hid_t dapl_id) {
  return lib().H5Dopen2(loc_id, name, dapl_id);
}
herr_t H5Dwrite(hid_t dset_id, hid_t mem_type_id, hid_t mem_space_id, hid_t file_space_id,
                hid_t dxpl_id, const void* buf) {
  return lib().H5Dwrite(dset_id, mem_type_id, mem_space_id, file_space_id, dxpl_id, buf);
}
hid_t H5Dget_space(hid_t dset_id) { return lib().H5Dget_space(dset_id); }
herr_t H5Dclose(hid_t dset_id) { return lib().H5Dclose(dset_id); }
hid_t H5Acreate2(hid_t loc_id, const char* attr_name, hid_t type_id, hid_t space_id, hid_t acpl_id,
                 hid_t aapl_id) {
  return lib().H5Acreate2(loc_id, attr_name, type_id, space_id, acpl_id, aapl_id);
}
hid_t H5Aopen(hid_t obj_id, const char* attr_name, hid_t aapl_id) {
  return lib().H5Aopen(obj_id, attr_name, aapl_id);
}
htri_t H5Aexists(hid_t obj_id, const char* attr_name) { return lib().H5Aexists(obj_id, attr_name); }
herr_t H5Awrite(hid_t attr_id, hid_t type_id, const void* buf) {
  return lib().H5Awrite(attr_id, type_id, buf);
}
herr_t H5Aread(hid_t attr_id, hid_t type_id, void* buf) {
  return lib().H5Aread(attr_id, type_id, buf);
}
hid_t H5Aget_type(hid_t attr_id) { return lib().H5Aget_type(attr_id); }
herr_t H5Aclose(hid_t attr_id) { return lib().H5Aclose(attr_id); }
hid_t H5Tcopy(hid_t type_id) { return lib().H5Tcopy(type_id); }
herr_t H5Tset_size(hid_t type_id, size_t size) { return lib().H5Tset_size(type_id, size); }
size_t H5Tget_size(hid_t type_id) { return lib().H5Tget_size(type_id); }
herr_t H5Tclose(hid_t type_id) { return lib().H5Tclose(type_id); }

}  // extern "C"
