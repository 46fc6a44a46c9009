#!/usr/bin/python3
"""An independent Modbus server (pymodbus) for plcfi's backend tests.

Discrete inputs 0..7 read 1,0,1,1,0,0,1,0; input registers 0..3 read 100, 200, 300,
65535; coils and holding registers start at 0 and keep what is written.
usage: modbus_test_server.py --tcp PORT | --rtu DEVICE [--baud 19200]
"""
import argparse
import logging
import sys

from pymodbus.datastore import (ModbusSequentialDataBlock, ModbusServerContext,
                                ModbusSlaveContext)
from pymodbus.transaction import ModbusRtuFramer

try:
    from pymodbus.server import StartSerialServer, StartTcpServer
except ImportError:  # older layout
    from pymodbus.server.sync import StartSerialServer, StartTcpServer


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tcp", type=int)
    ap.add_argument("--rtu")
    ap.add_argument("--baud", type=int, default=19200)
    a = ap.parse_args()
    logging.basicConfig(level=logging.ERROR)
    # pymodbus blocks are addressed from 1 for address 0 (zero_mode=False default).
    store = ModbusSlaveContext(
        di=ModbusSequentialDataBlock(1, [1, 0, 1, 1, 0, 0, 1, 0] + [0] * 56),
        co=ModbusSequentialDataBlock(1, [0] * 64),
        hr=ModbusSequentialDataBlock(1, [0] * 64),
        ir=ModbusSequentialDataBlock(1, [100, 200, 300, 65535] + [0] * 60))
    context = ModbusServerContext(slaves=store, single=True)
    print("ready", flush=True)
    if a.tcp:
        StartTcpServer(context=context, address=("127.0.0.1", a.tcp))
    elif a.rtu:
        StartSerialServer(context=context, framer=ModbusRtuFramer, port=a.rtu, baudrate=a.baud,
                          bytesize=8, parity="N", stopbits=1, timeout=0.05)
    else:
        ap.error("--tcp PORT or --rtu DEVICE")


if __name__ == "__main__":
    sys.exit(main())
