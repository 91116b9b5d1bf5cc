"""Reading the stressing energy from YADE's interactions (Eqs. 14-16): reader.py is the one
interface (ContactReader), table.py the rows it keeps, law.py the physics of one contact,
each.py and arrays.py its two read paths, zeroed_rows.py which rows are zeroed pairs and which of
those sleep (kept from read to read), loading.py what a read tells the judge."""
from yadebreak.engine.contacts.law import HertzMindlinWork, own_share, total_work
from yadebreak.engine.contacts.loading import Loading, Strongest, StrongestContacts
from yadebreak.engine.contacts.reader import SMALL, ContactReader
from yadebreak.engine.contacts.table import FIELDS

__all__ = ["ContactReader", "FIELDS", "HertzMindlinWork", "Loading", "SMALL",
           "Strongest", "StrongestContacts", "own_share", "total_work"]
