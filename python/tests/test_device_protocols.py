"""The CUDA side of the array protocols, checked without a GPU: views of a
pretend device buffer (its address is never dereferenced)."""

import gc

import numpy as np
import pytest

from psc import dlpack

ADDRESS = 0x7F0000001000  # a made-up device address


class FakeBatch:
    """Stands in for batch.Batch: a stream handle and a synchronize() counter."""

    def __init__(self, stream=0):
        self.stream = stream
        self.synchronized = 0

    def synchronize(self):
        self.synchronized += 1


def device_view(batch, shape=(4,), dtype=np.int32, device=0):
    return dlpack.BufferView(batch, ADDRESS, shape, dtype, device)


def test_cuda_array_interface():
    view = device_view(FakeBatch(), shape=(2, 3, 4, 5), dtype=np.uint8)
    interface = view.__cuda_array_interface__
    assert interface == {
        "shape": (2, 3, 4, 5),
        "typestr": "|u1",
        "data": (ADDRESS, False),
        "version": 3,
        "strides": None,
        "stream": 1,  # the default stream is reported as the legacy default stream
    }
    assert device_view(FakeBatch(stream=0xABC)).__cuda_array_interface__["stream"] == 0xABC
    assert not hasattr(view, "__array_interface__")
    assert view.__dlpack_device__() == (dlpack.DEVICE_CUDA, 0)
    assert device_view(FakeBatch(), device=3).__dlpack_device__() == (dlpack.DEVICE_CUDA, 3)


@pytest.mark.parametrize(
    "batch_stream, consumer_stream, waits",
    [
        (0, None, False),  # both on the legacy default stream
        (0, 1, False),
        (0, 0xABC, True),  # another stream waits for the batch's work
        (0xABC, 0xABC, False),
        (0xABC, None, True),
        (0xABC, -1, False),  # -1: the consumer asks for no synchronisation
    ],
)
def test_dlpack_orders_the_batch_work_before_the_consumer_stream(batch_stream, consumer_stream, waits):
    batch = FakeBatch(batch_stream)
    capsule = device_view(batch).__dlpack__(stream=consumer_stream)
    assert batch.synchronized == (1 if waits else 0)
    del capsule


def test_dlpack_refuses_copies_and_other_devices():
    view = device_view(FakeBatch())
    with pytest.raises(BufferError):
        view.__dlpack__(copy=True)
    with pytest.raises(BufferError):
        view.__dlpack__(dl_device=(dlpack.DEVICE_CPU, 0))
    before = len(dlpack._exported)
    capsule = view.__dlpack__(max_version=(1, 0), dl_device=(dlpack.DEVICE_CUDA, 0))  # answered unversioned
    assert len(dlpack._exported) == before + 1
    del capsule
    gc.collect()
    assert len(dlpack._exported) == before


def test_device_arrays_are_read_through_dlpack():
    producer = device_view(FakeBatch(stream=0xABC), shape=(4,), dtype=np.int32)
    assert dlpack.array_address(producer, (4,), np.int32, device=0, stream=0xABC) == ADDRESS
    assert producer.owner.synchronized == 0  # produced on the batch's own stream
    with pytest.raises(ValueError, match="DLPack device"):
        dlpack.array_address(producer, (4,), np.int32, device=1, stream=0)
    with pytest.raises(ValueError, match="dtype"):
        dlpack.array_address(producer, (4,), np.float32, device=0, stream=0)


def test_device_arrays_are_read_through_the_cuda_array_interface():
    class CudaArray:
        def __init__(self, stream):
            self.__cuda_array_interface__ = {
                "shape": (4,),
                "typestr": "<i4",
                "data": (ADDRESS, False),
                "version": 3,
                "strides": None,
                "stream": stream,
            }

    assert dlpack.array_address(CudaArray(None), (4,), np.int32, device=0, stream=0) == ADDRESS
    assert dlpack.array_address(CudaArray(1), (4,), np.int32, device=0, stream=0) == ADDRESS
    with pytest.raises(ValueError, match="set_stream"):
        dlpack.array_address(CudaArray(0xABC), (4,), np.int32, device=0, stream=0)
    with pytest.raises(TypeError, match="__cuda_array_interface__"):
        dlpack.array_address(np.zeros(4, dtype=np.int32).tolist(), (4,), np.int32, device=0, stream=0)
