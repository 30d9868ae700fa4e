from hairtool import interrupts

if __name__ == "__main__":  # not when multiprocessing re-imports it in a worker process
    interrupts.install()  # before the command line's modules load
    from hairtool.cli import entry

    entry()
