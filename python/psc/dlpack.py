"""Zero-copy exchange of plugin buffers with array libraries.

BufferView exports one of a batch's buffers (host memory for CPU batches,
device memory for CUDA batches) through the DLPack protocol (__dlpack__,
__dlpack_device__: torch.from_dlpack, jax.dlpack.from_dlpack, cupy,
numpy.from_dlpack) and through __cuda_array_interface__ (version 3) or
__array_interface__.  array_address() goes the other way: the address of a
foreign array, so that plugins can read actions where a framework wrote them.

DLPack is spoken with ctypes: a DLManagedTensor lives in Python memory, kept
(with the batch it points into) in _exported until the consumer calls its
deleter.
"""

import contextlib
import ctypes
from ctypes import POINTER, c_char_p, c_int32, c_int64, c_uint8, c_uint16, c_uint64, c_void_p

import numpy as np

DEVICE_CPU = 1  # kDLCPU
DEVICE_CUDA = 2  # kDLCUDA

_TYPE_CODES = {"i": 0, "u": 1, "f": 2}  # kDLInt, kDLUInt, kDLFloat


class DLDevice(ctypes.Structure):
    _fields_ = [("device_type", c_int32), ("device_id", c_int32)]


class DLDataType(ctypes.Structure):
    _fields_ = [("code", c_uint8), ("bits", c_uint8), ("lanes", c_uint16)]


class DLTensor(ctypes.Structure):
    _fields_ = [
        ("data", c_void_p),
        ("device", DLDevice),
        ("ndim", c_int32),
        ("dtype", DLDataType),
        ("shape", POINTER(c_int64)),
        ("strides", POINTER(c_int64)),
        ("byte_offset", c_uint64),
    ]


_Deleter = ctypes.CFUNCTYPE(None, c_void_p)


class DLManagedTensor(ctypes.Structure):
    _fields_ = [("dl_tensor", DLTensor), ("manager_ctx", c_void_p), ("deleter", _Deleter)]


_CAPSULE_NAME = b"dltensor"
_PyCapsule_Destructor = ctypes.CFUNCTYPE(None, c_void_p)


def _python_api(name: str, restype, argtypes):
    # A function object of our own (indexing makes a new one), so that other
    # users of ctypes.pythonapi cannot change its signature under us.
    function = ctypes.pythonapi[name]
    function.restype = restype
    function.argtypes = argtypes
    return function


_capsule_new = _python_api("PyCapsule_New", ctypes.py_object, [c_void_p, c_char_p, _PyCapsule_Destructor])
_capsule_pointer = _python_api("PyCapsule_GetPointer", c_void_p, [ctypes.py_object, c_char_p])
# The destructor gets the capsule as a raw address: wrapping a capsule that is
# being deallocated in a Python object would resurrect it.
_capsule_is_valid_raw = _python_api("PyCapsule_IsValid", ctypes.c_int, [c_void_p, c_char_p])
_capsule_pointer_raw = _python_api("PyCapsule_GetPointer", c_void_p, [c_void_p, c_char_p])

# address of each exported DLManagedTensor -> what must live until its deleter runs
_exported = {}


def _release(managed_address: int) -> None:
    _exported.pop(managed_address, None)


@_Deleter
def _delete_managed(managed_address):
    _release(managed_address)


@_PyCapsule_Destructor
def _destroy_capsule(capsule_address):
    # A consumer renames the capsule to "used_dltensor" and owns the tensor from
    # then on; a capsule that dies still named "dltensor" was never consumed.
    if _capsule_is_valid_raw(capsule_address, _CAPSULE_NAME):
        _release(_capsule_pointer_raw(capsule_address, _CAPSULE_NAME))


def _row_major_strides(shape) -> tuple:
    strides, step = [], 1
    for extent in reversed(shape):
        strides.append(step)
        step *= extent
    return tuple(reversed(strides))


class BufferView:
    """One plugin buffer as an array that frameworks can view without copying.

    owner: the Batch (kept alive by every export); address: host or device
    address; device: -1 for host memory, else the CUDA device ordinal.
    """

    def __init__(self, owner, address: int, shape, dtype, device: int):
        self.owner = owner
        self.address = int(address)
        self.shape = tuple(int(s) for s in shape)
        self.dtype = np.dtype(dtype)
        self.device = device

    @property
    def nbytes(self) -> int:
        return int(np.prod(self.shape)) * self.dtype.itemsize

    def __repr__(self) -> str:
        where = "host" if self.device < 0 else f"cuda:{self.device}"
        return f"BufferView({self.shape}, {self.dtype}, {where}, 0x{self.address:x})"

    def numpy(self) -> np.ndarray:
        """A numpy view (host buffers only) that keeps the batch alive."""
        if self.device >= 0:
            raise TypeError("a device buffer has no numpy view; use torch/jax/cupy through DLPack")
        return np.asarray(self)

    # --- the array interfaces

    @property
    def __array_interface__(self) -> dict:
        if self.device >= 0:
            raise AttributeError("device memory has no __array_interface__")
        return {"shape": self.shape, "typestr": self.dtype.str, "data": (self.address, False), "version": 3}

    @property
    def __cuda_array_interface__(self) -> dict:
        if self.device < 0:
            raise AttributeError("host memory has no __cuda_array_interface__")
        # Work is queued on the batch's stream; consumers wait on it (1: the legacy default stream).
        return {
            "shape": self.shape,
            "typestr": self.dtype.str,
            "data": (self.address, False),
            "version": 3,
            "strides": None,
            "stream": self.owner.stream or 1,
        }

    def __dlpack_device__(self) -> tuple:
        return (DEVICE_CPU, 0) if self.device < 0 else (DEVICE_CUDA, self.device)

    def __dlpack__(self, stream=None, *, max_version=None, dl_device=None, copy=None):
        # max_version is accepted and answered with the unversioned capsule,
        # which every DLPack consumer reads.
        if copy:
            raise BufferError("psc buffers are exported without copying (copy=True is not supported)")
        if dl_device is not None and tuple(dl_device) != self.__dlpack_device__():
            raise BufferError(f"the buffer is on {self.__dlpack_device__()}, not {tuple(dl_device)}")
        if self.device >= 0:
            self._order_before(stream)
        return self._capsule()

    def _order_before(self, stream) -> None:
        # DLPack: the data must be ready on the consumer's stream.  Queued plugin
        # work is on the batch's stream; any other stream waits for all of it.
        if stream == -1:
            return
        consumer = 1 if stream in (None, 0) else stream
        if consumer != (self.owner.stream or 1):
            self.owner.synchronize()

    def _capsule(self):
        ndim = len(self.shape)
        shape = (c_int64 * ndim)(*self.shape)
        strides = (c_int64 * ndim)(*_row_major_strides(self.shape))
        managed = DLManagedTensor()
        managed.dl_tensor.data = self.address
        device_type, device_id = self.__dlpack_device__()
        managed.dl_tensor.device = DLDevice(device_type, device_id)
        managed.dl_tensor.ndim = ndim
        managed.dl_tensor.dtype = DLDataType(_TYPE_CODES[self.dtype.kind], self.dtype.itemsize * 8, 1)
        managed.dl_tensor.shape = shape
        managed.dl_tensor.strides = strides
        managed.dl_tensor.byte_offset = 0
        managed.manager_ctx = None
        managed.deleter = _delete_managed
        address = ctypes.addressof(managed)
        _exported[address] = (managed, shape, strides, self.owner)
        return _capsule_new(address, _CAPSULE_NAME, _destroy_capsule)


def _contiguous(shape, strides, itemsize: int) -> bool:
    return strides is None or tuple(strides) == tuple(s * itemsize for s in _row_major_strides(shape))


def array_address(array, shape, dtype, device: int, stream: int) -> int:
    """The address of a foreign C-contiguous array of this shape and dtype.

    device: -1 for host memory (numpy, CPU torch tensors), else the CUDA
    device the array must live on.  stream: the stream the caller's plugin
    work is queued on, so that a DLPack producer orders its writes before it.
    The caller must keep `array` alive while the plugin may read it.
    """
    shape = tuple(shape)
    dtype = np.dtype(dtype)
    if hasattr(array, "__dlpack__"):
        return _dlpack_address(array, shape, dtype, device, stream)
    interface_name = "__array_interface__" if device < 0 else "__cuda_array_interface__"
    interface = getattr(array, interface_name, None)
    if interface is None:
        where = "host" if device < 0 else f"CUDA device {device}"
        raise TypeError(f"expected an array on {where} with __dlpack__ or {interface_name}, got {type(array).__name__}")
    got_shape, got_dtype = tuple(interface["shape"]), np.dtype(interface["typestr"])
    if got_shape != shape or got_dtype != dtype:
        raise ValueError(f"expected shape {shape} and dtype {dtype}, got {got_shape} {got_dtype}")
    if not _contiguous(shape, interface.get("strides"), dtype.itemsize):
        raise ValueError("the array must be C-contiguous")
    producer_stream = interface.get("stream")
    if device >= 0 and producer_stream not in (None, stream or 1):
        raise ValueError(
            f"the array was produced on stream {producer_stream} but the environment runs on stream {stream or 1}: "
            "call env.set_stream() with the producer's stream, or pass an object with __dlpack__"
        )
    return int(interface["data"][0])


def _current_device(array, device: int):
    """PyTorch exports a CUDA tensor only while its device is the current one:
    make it so for a batch on another GPU than the caller's current device."""
    if type(array).__module__.split(".")[0] == "torch":
        import torch

        return torch.cuda.device(device)
    return contextlib.nullcontext()


def _dlpack_address(array, shape, dtype, device: int, stream: int) -> int:
    device_type, device_id = array.__dlpack_device__()
    expected = (DEVICE_CPU, 0) if device < 0 else (DEVICE_CUDA, device)
    if (int(device_type), int(device_id)) != expected:
        raise ValueError(f"the array is on DLPack device {(int(device_type), int(device_id))}, expected {expected}")
    if device < 0:
        capsule = array.__dlpack__()
    else:
        with _current_device(array, device):
            capsule = array.__dlpack__(stream=stream or 1)
    # The capsule stays unconsumed: when it dies its producer releases only
    # this export, while `array` itself keeps the memory.
    tensor = DLManagedTensor.from_address(_capsule_pointer(capsule, _CAPSULE_NAME)).dl_tensor
    got_shape = tuple(tensor.shape[i] for i in range(tensor.ndim))
    code = {v: k for k, v in _TYPE_CODES.items()}.get(tensor.dtype.code)
    got_dtype = np.dtype(f"{code}{tensor.dtype.bits // 8}") if code and tensor.dtype.lanes == 1 else None
    if got_shape != shape or got_dtype != dtype:
        raise ValueError(f"expected shape {shape} and dtype {dtype}, got {got_shape} {got_dtype}")
    strides = None if not tensor.strides else tuple(tensor.strides[i] * dtype.itemsize for i in range(tensor.ndim))
    if not _contiguous(shape, strides, dtype.itemsize):
        raise ValueError("the array must be C-contiguous")
    return int(tensor.data or 0) + int(tensor.byte_offset)
