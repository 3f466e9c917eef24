"""Detail lines that a terminal shows in passing: validate's default view (issue 32, item 4).

A default `make validate` prints a line or two per phase -- the runs, the verdict, the sweeps, the
stability limits, the extreme probes, the report -- and every failure, KNOWN row and finding in
full; the detail of each phase (each sweep's cheapest settings, each bisection's limit, each
probe's outcome) is in the report and in reports/*.tsv, and `validate -v` prints it as before.
Transient is the stream that detail goes to: on a terminal each line it is given replaces the
last on one status line, so a long phase still shows what it is doing; off a terminal (a log, CI)
it is dropped.
"""
import shutil

CLEAR = "\r\x1b[K"      # back to the start of the line, erase it


class Transient:
    """A text stream whose complete lines are shown one at a time on out's status line when out is
    a terminal (cut to its width, so the line never wraps and \\r rubs it out whole), dropped
    otherwise; a line for which keep(line) is true is printed to out whole, and stays (an
    interrupted batch's account of what it stopped).  close() erases the status line; a line
    printed to out afterwards starts clean."""

    def __init__(self, out, tty=None, keep=None):
        self.out = out
        self.tty = out.isatty() if tty is None else tty
        self.keep = keep
        self._partial, self._shown = "", False

    def write(self, text):
        self._partial += text
        *lines, self._partial = self._partial.split("\n")
        for line in lines:
            if line.strip() and self.keep and self.keep(line):
                self.close()
                self.out.write(line + "\n")
                self.out.flush()
            elif self.tty and line.strip():
                width = max(20, shutil.get_terminal_size((80, 24)).columns - 1)
                self.out.write(CLEAR + line[:width])
                self.out.flush()
                self._shown = True
        return len(text)

    def flush(self):
        if self.tty:
            self.out.flush()

    def isatty(self):
        """False: a writer that asks prints plain lines, which this stream shows in passing."""
        return False

    def close(self):
        if self._shown:
            self.out.write(CLEAR)
            self.out.flush()
            self._shown = False
